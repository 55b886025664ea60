/// \file thermal_layer.hpp
/// \brief 2D thermal model of the layer under the moving spot (SPEC §5 last bullet; PATH eq. 5): the
/// model class, which cuts the spot stream into steps and runs the window (layer_window.hpp), the
/// solver (lod_solver.hpp), the melted record (melted_record.hpp) and the melt-pool measures
/// (melt_pool.hpp). Its results are plain structs (thermal_results.hpp); the analytic reference is
/// steady_moving_spot.hpp.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "scanhead/common/chunk.hpp"
#include "scanhead/common/chunk_sequencer.hpp"
#include "scanhead/thermal/layer_window.hpp"
#include "scanhead/thermal/lod_solver.hpp"
#include "scanhead/thermal/melt_pool.hpp"
#include "scanhead/thermal/melted_record.hpp"
#include "scanhead/thermal/thermal_config.hpp"
#include "scanhead/thermal/thermal_results.hpp"

namespace scanhead
{
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
  const MeltPoolStats& stats() const { return pool_stats_.stats(); }
  ThermalEnergy energy() const;  ///< with stored_j summed now

  std::uint64_t meltedCellCount() const { return record_.count(); }
  /// \brief meltedCellCount() · cell² [m²]
  double meltedArea() const { return static_cast<double>(record_.count()) * window_.cell_m * window_.cell_m; }
  bool isMelted(const Eigen::Vector2d& p) const;  ///< the global record at the cell holding \p p
  double riseAt(const Eigen::Vector2d& p) const;  ///< bilinear T at \p p in the window, 0 outside [K]
  ThermalWindow window() const;
  MeltedRaster meltedRaster() const;
  const ThermalConfig& config() const { return config_; }

private:
  struct Pending
  {
    SpotSample sample;
    std::uint64_t index = 0;
  };

  void pushSample(const SpotSample& s, std::uint64_t index);
  void runStep(std::size_t count, const SpotSample* next);
  void depositPoint(double x, double y, double energy_j, CellBox& src_box);
  void postStep(const LossHalfStep& loss, int& peak_i, int& peak_j);

  ThermalConfig config_;
  // Derived constants.
  double w_ = 0.0;                                                       ///< spot radius [m]
  double kappa_s_ = 0.0, kappa_p_ = 0.0, loss_ = 0.0, melt_rise_ = 0.0;  ///< κ_s, λ_s: of a melted cell (phase_switch)
  double lambda_s_ = 0.0;
  bool keep_energy_ = false;
  // Model state.
  LayerWindow window_;  ///< fields (n × n, row-major), placement, active box
  MeltedRecord record_;
  std::vector<double> gx_, gy_;         ///< footprint weights scratch
  std::vector<std::int32_t> switched_;  ///< cells switched this step (flat index)
  // Stream.
  ChunkSequencer sequence_;  ///< samples already simulated, gaps to fill
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
  MeltPoolAccumulator pool_stats_;
  ThermalEnergy books_;  ///< stored_j filled by energy()
};
}  // namespace scanhead
