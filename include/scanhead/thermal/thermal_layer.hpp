/// \file thermal_layer.hpp
/// \brief 2D thermal model of the layer under the moving spot (SPEC §5 last bullet; PATH eq. 5).
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "scanhead/common/chunk.hpp"
#include "scanhead/thermal/thermal_config.hpp"

namespace scanhead
{
/// \brief One thermal time step (step_samples NC periods, fewer for the last one at finish()).
struct ThermalStep
{
  std::uint64_t first_index = 0;  ///< global index of the step's first sample
  std::uint32_t samples = 0;      ///< NC samples in the step
  double time_s = 0.0;            ///< end of the step, (first_index + samples)·Ts [s]
  double peak_k = 0.0;            ///< highest rise in the window at the end of the step [K]
  double length_m = 0.0;          ///< melt-pool extent along the scan direction (0 below melting) [m]
  double width_m = 0.0;           ///< melt-pool extent across it [m]
  bool laser_on = false;          ///< some sample of the step had power
  bool steady = false;            ///< counted in the steady means (laser on all the step, past settle_time_s)
  bool pool_at_window_edge = false;  ///< the melt pool reached the window edge: length/width truncated
};

/// \brief Mean and spread of the steady steps, maxima over all steps.
struct MeltPoolStats
{
  std::uint64_t steps = 0;          ///< thermal steps run
  std::uint64_t laser_on_steps = 0;
  std::uint64_t melting_steps = 0;  ///< steps whose peak was above melting
  std::uint64_t steady_steps = 0;   ///< steps in the means below
  double steady_length_mean_m = 0.0, steady_length_std_m = 0.0;
  double steady_width_mean_m = 0.0, steady_width_std_m = 0.0;
  double steady_peak_mean_k = 0.0, steady_peak_std_k = 0.0;
  double max_length_m = 0.0, max_width_m = 0.0, max_peak_k = 0.0;  ///< over all steps
};

/// \brief Energy books [J], cumulative since construction / reset().
///
/// absorbed + phase_switch = outside + stored + lost + left_window + truncated, to rounding (residual()).
struct ThermalEnergy
{
  double absorbed_j = 0.0;      ///< Σ A·P·Ts of all samples
  double outside_j = 0.0;       ///< the part of it whose footprint fell outside the window
  double stored_j = 0.0;        ///< now in the window, ∫ h·κ·T dA
  double lost_j = 0.0;          ///< through the loss term ∫∫ h·(λ_s/δ²)·T dA dt
  double phase_switch_j = 0.0;  ///< added by powder → solid switches at constant T, Σ h·(κ_melted − κ_p)·T·dA
  double left_window_j = 0.0;   ///< carried out of the window by its re-centring
  double truncated_j = 0.0;     ///< dropped with cells below active_threshold_k outside the hot box
  double residual_j() const
  {
    return absorbed_j + phase_switch_j - outside_j - stored_j - lost_j - left_window_j - truncated_j;
  }
};

/// \brief The window's fields as plain arrays, row-major (row j = y, row 0 at the lowest y).
///
/// Cells are those of the global grid of pitch cell_m anchored at the plane origin: cell (i, j) of the
/// window is global cell (origin_i + i, origin_j + j), covering [(origin_i + i)·cell_m, +cell_m) in x.
struct ThermalWindow
{
  double cell_m = 0.0;
  std::int64_t origin_i = 0, origin_j = 0;
  int width = 0, height = 0;
  std::vector<double> rise_k;        ///< temperature rise over the bed T [K]
  std::vector<std::uint8_t> solid;   ///< 1 once melted (solid properties), 0 powder
};

/// \brief The cells ever melted (global record) as a raster over their bounding box (same grid as ThermalWindow).
struct MeltedRaster
{
  double cell_m = 0.0;
  std::int64_t origin_i = 0, origin_j = 0;
  int width = 0, height = 0;
  std::vector<std::uint8_t> melted;  ///< row-major, 1 = melted
  std::uint64_t count = 0;           ///< melted cells
};

/// \brief PATH eq. 5 on a window of the layer that follows the spot.
///
/// \f[ \kappa\,\partial_t T - \nabla\cdot(\lambda \nabla T) + \frac{\lambda_{solide}}{\delta^2}\,T = \frac{q}{h},
///     \qquad q = \frac{2 A P}{\pi w^2}\,e^{-2 r^2/w^2}\quad\text{(PATH eq. 3, f = 2)} \f]
/// T the rise over the bed, κ = ρ c_p and λ those of powder or melted cell (PATH eq. 1; what a
/// switch does: ThermalConfig::phase_switch), a cell switching, irreversibly, once T > melt − ambient;
/// the loss term uses λ_solide everywhere, as PATH. Zero normal flux at the window edges (PATH's
/// adiabatic edge ∂Σ becomes the window's edge).
///
/// Space: 5-point finite volumes on the cells, face conductivity the arithmetic (default) or
/// harmonic mean of the two cells (ThermalConfig::face_conductivity).
/// Time, per step dt: T ← f·T with f = exp(−½dt·λ_s/(δ²κ)) (half the loss, exactly), + the step's
/// source, then backward Euler on the diffusion split by direction (locally one-dimensional: an x
/// solve then a y solve, the order alternating each step; Thomas solves, O(cells)), then T ← f·T.
/// Each 1-D factor is an M-matrix: unconditionally stable and T ≥ 0 whatever dt/cell² (no
/// oscillations). Diffusion is first order in dt (and the split adds a steady error dt²·AxAy·T:
/// −12 % on a dwell's peak at dt = 100 µs, 5 µm cells; −1.3 % at 10 µs); the loss is exact and, for
/// one material, commutes with the diffusion, so a dwell's energy is second-order accurate. The
/// books close to rounding.
/// The solve covers only the box of cells above active_threshold_k and the step's footprint, grown
/// by 2 + 3·sqrt(a_max·dt)/cell cells (adiabatic at the box edge too; cells outside it are exactly 0,
/// the ones dropped are booked as truncated_j).
///
/// Source: sample k carries A·P_k·Ts, spread along the segment from its actual spot to that of
/// sample k+1 in sub-steps ≤ max_substep_radii·w (as the energy map; the last one is a dwell), each
/// point-sampled on the cell centres within source_truncation_radii·w (square) and renormalised to
/// sum exactly; the part off the window is booked as outside_j.
///
/// Window: window_m square, on the global grid; when a powered point of a step comes within
/// recentre_margin_m of the edge it re-centres on the step's powered points by whole cells: the fields
/// shift, cells leaving carry their energy away (left_window_j), cells entering start at T = 0 and
/// powder unless the global sparse record of melted cells says solid. Truncation this implies: the
/// real bed has no edge at the window, so heat reaching the edge is held in (too warm near it) and
/// the tail more than ~window/2 behind the spot is forgotten (a later track passing there after the
/// window moved sees it cold but solid). The pool must fit in window/2 behind the spot
/// (pool_at_window_edge flags it): 200 W, default bed, pools of 0.33–0.6 mm: the same steady length
/// to 0.1 µm for windows of 1.5, 2 and 4 mm; a 0.7 mm window cuts the 0.59 mm pool at 2 m/s to 0.46 mm.
/// The window does not move while the laser is off (cooling goes on where the heat is).
///
/// Melt pool, each step: from the hottest cell, along the scan direction (that of the last two
/// powered samples) and back, bilinear T sampled every cell until it drops below melting, the
/// bracket halved 3 times and the crossing interpolated linearly (length); across, the same from
/// points every cell along that segment, the widest (width). Only the region connected to the peak
/// along those lines counts.
///
/// Streaming: the stream is cut into steps by sample count from the first sample seen, so any
/// chunking gives the same result bit for bit. Samples already seen are skipped; a gap is filled
/// with laser-off samples at the last position. Not modelled: oblique incidence (the spot is
/// round), temperature-dependent properties, latent heat, evaporation, the layer below (beyond δ).
class ThermalLayer
{
public:
  /// \throws ConfigError from config.validate()
  explicit ThermalLayer(const ThermalConfig& config);
  void reset();
  /// \throws NumericalError on a sample with non-finite or negative power, or non-finite position
  ///         while it has power (names its global index)
  /// \throws InputError on a chunk period that is not > 0 or changes in the stream
  void process(const SpotChunk& chunk);
  /// \brief Runs the last, possibly shorter, step (call at the end of the stream; the last sample is
  /// a dwell). process() may go on afterwards: the next sample starts a new step.
  void finish();

  /// \brief Steps completed by the last process() / finish() call.
  const std::vector<ThermalStep>& recentSteps() const { return recent_; }
  const ThermalStep& lastStep() const { return last_; }
  const MeltPoolStats& stats() const { return stats_; }
  ThermalEnergy energy() const;  ///< with stored_j summed now

  std::uint64_t meltedCellCount() const { return record_.count; }
  double meltedArea() const { return static_cast<double>(record_.count) * cell_ * cell_; }  ///< [m²]
  bool isMelted(const Eigen::Vector2d& p) const;  ///< the global record at the cell holding \p p
  double riseAt(const Eigen::Vector2d& p) const;  ///< bilinear T at \p p in the window, 0 outside [K]
  ThermalWindow window() const;
  MeltedRaster meltedRaster() const;
  const ThermalConfig& config() const { return config_; }

private:
  struct Box
  {
    int i0 = 0, i1 = -1, j0 = 0, j1 = -1;  ///< inclusive; empty when i1 < i0
    bool empty() const { return i1 < i0 || j1 < j0; }
  };
  struct Record
  {
    using Tile = std::array<std::uint64_t, 64>;  ///< 64 × 64 cells, bit i of word j
    std::unordered_map<std::int64_t, Tile> tiles;
    std::uint64_t count = 0;
    bool get(std::int64_t gi, std::int64_t gj) const;
    void set(std::int64_t gi, std::int64_t gj);  ///< (count += 1 if new)
  };
  struct Pending
  {
    SpotSample sample;
    std::uint64_t index = 0;
  };

  void pushSample(const SpotSample& s, std::uint64_t index);
  void runStep(std::size_t count, const SpotSample* next);
  void placeWindow(const Eigen::Vector2d& centre);
  void depositPoint(double x, double y, double energy_j, Box& src_box);
  void sweepX(const Box& b, bool first, double dt, double& lost_j);
  void sweepY(const Box& b, bool first, double dt, double& lost_j);
  void postStep(int& peak_i, int& peak_j);
  void updateFaces(int i, int j);
  void measurePool(int peak_i, int peak_j, ThermalStep& step) const;
  double sampleLocal(double u, double v) const;  ///< bilinear T at local cell coordinates (centres at k + 0.5)
  void addStats(const ThermalStep& step);

  ThermalConfig config_;
  // Derived constants.
  int n_ = 0;              ///< window side [cells]
  double cell_ = 0.0, w_ = 0.0, h_area_ = 0.0;  ///< cell [m], spot radius [m], h·cell² [m³]
  double kappa_s_ = 0.0, kappa_p_ = 0.0, loss_ = 0.0, melt_rise_ = 0.0;  ///< κ_s, λ_s: of a melted cell (phase_switch)
  double lambda_s_ = 0.0;
  bool keep_energy_ = false;
  double decay_s_ = 1.0, decay_p_ = 1.0;  ///< f = exp(−½dt·λ_s/(δ²κ)) of this step, solid / powder
  double lost_s_ = 0.0, lost_p_ = 0.0;    ///< (1 − f)·κ·h·cell² [J/K]
  double (*face_)(double, double) = nullptr;  ///< face conductivity rule
  // Window fields (n_ × n_, row-major).
  std::vector<double> t_;        ///< rise [K]
  std::vector<double> inv_kappa_;  ///< 1/κ [m³·K/J]
  std::vector<double> lambda_;   ///< cell conductivity [W/(m·K)]
  std::vector<double> fx_, fy_;  ///< face conductivities: fx_ between (i, j) and (i+1, j) at j·n + i, fy_ (i, j)–(i, j+1)
  std::vector<std::uint8_t> solid_;
  std::vector<double> src_;      ///< energy deposited this step [J]
  std::vector<double> cp_;       ///< Thomas scratch
  std::vector<double> gx_, gy_;  ///< footprint weights scratch
  std::vector<std::int32_t> switched_;  ///< cells switched this step (flat index)
  bool placed_ = false;
  std::int64_t oi_ = 0, oj_ = 0;  ///< global index of window cell (0, 0)
  Box box_;                       ///< active box (T = 0 outside)
  Record record_;
  // Stream.
  bool started_ = false;
  std::uint64_t next_index_ = 0;
  double period_s_ = 0.0;
  std::vector<Pending> pending_;
  std::uint64_t step_count_ = 0;
  bool burst_on_ = false;
  std::uint64_t burst_start_index_ = 0;
  bool has_on_pos_ = false;
  Eigen::Vector2d last_on_pos_ = Eigen::Vector2d::Zero();
  Eigen::Vector2d last_pos_ = Eigen::Vector2d::Zero();  ///< last finite position (gap filling)
  Eigen::Vector2d dir_ = Eigen::Vector2d(1.0, 0.0);
  // Outputs.
  std::vector<ThermalStep> recent_;
  ThermalStep last_;
  MeltPoolStats stats_;
  double sum_len_ = 0.0, sum_len2_ = 0.0, sum_wid_ = 0.0, sum_wid2_ = 0.0, sum_pk_ = 0.0, sum_pk2_ = 0.0;
  ThermalEnergy books_;  ///< stored_j filled by energy()
};

/// \brief Steady rise T(ξ, η) [K] of the layer with a melted cell's properties everywhere (κ, λ =
/// kappaMelted(), conductivityMelted(): κ_s, λ_s unless "consolidate"; no switch, infinite bed)
/// under the spot moving at constant \p speed_m_s along +ξ, at (ξ, η) from the spot centre.
///
/// The moving-frame equation κ v ∂T/∂ξ + λ ΔT − (λ_s/δ²) T = −q/h has for a point source Q the
/// solution \f$ T = \frac{Q}{2\pi\lambda h} e^{-v\xi/(2a)} K_0\!\left(\rho\sqrt{(v/2a)^2 + m^2}\right) \f$,
/// a = λ/κ, m² = λ_s/(λ δ²). Convolved with the Gaussian spot it is evaluated as the time integral
/// \f[ T(\xi,\eta) = \frac{A P}{h\kappa}\int_0^\infty \frac{e^{-t/\tau}}{2\pi\sigma^2(t)}
///     \exp\!\left(-\frac{(\xi + v t)^2 + \eta^2}{2\sigma^2(t)}\right) dt,\quad \sigma^2 = \frac{w^2}{4} + 2 a t,\;
///     \tau = \frac{\kappa\delta^2}{\lambda_s} \f]
/// (adaptive Simpson, absolute tolerance 1e-7·(melt rise)). \p speed_m_s may be 0 (dwell).
double steadyMovingSpotRise(const ThermalConfig& config, double power_w, double speed_m_s, double xi_m, double eta_m);

/// \brief Melt pool of steadyMovingSpotRise: the region above melt − ambient.
struct SteadyMeltPool
{
  double peak_k = 0.0;     ///< highest steady rise (on the axis) [K]
  double peak_xi_m = 0.0;  ///< where [m] (≤ 0: behind the spot centre)
  double front_m = 0.0;    ///< ξ of the front on the axis [m]
  double rear_m = 0.0;     ///< ξ of the rear [m]
  double length_m = 0.0;   ///< front − rear (0 if the peak is below melting) [m]
  double width_m = 0.0;    ///< widest extent across [m]
};
/// \brief Root finding (bisection to 1e-9 m) on steadyMovingSpotRise; width the maximum over ξ.
SteadyMeltPool steadyMeltPool(const ThermalConfig& config, double power_w, double speed_m_s);
}  // namespace scanhead
