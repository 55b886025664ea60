/// \file run_metrics.hpp
/// \brief The figures of a run: counts, energies, and per-corner speed drop and contour error.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "scanhead/common/chunk.hpp"
#include "scanhead/common/chunk_sequencer.hpp"
#include "scanhead/job/scan_job.hpp"
#include "scanhead/metrics/layer_quality.hpp"
#include "scanhead/nc/nc_stats.hpp"
#include "scanhead/thermal/thermal_results.hpp"

namespace scanhead
{
struct CornerPathStats
{
  double min_speed_mps = 0.0;        ///< lowest tangential speed near the corner [m/s]
  double max_contour_error_m = 0.0;  ///< distance from the commanded corner to the path [m]
};

struct CornerReport
{
  Corner corner;
  CornerPathStats setpoint;  ///< Q_filt2 through the direct model
  CornerPathStats actual;    ///< after the servo
  CornerPathStats theory;    ///< NC §3.2–3.3 closed forms
  double energy_peak_jpm2 =
      0.0;  ///< max E on the map within (actual contour error + spot radius) of the commanded corner [J/m²]
};

/// \brief Where the stream of an incomplete run stopped (a stage died or hung mid-job).
struct StreamGap
{
  std::string streams;              ///< the inputs that stopped, with the last sample seen on each
  std::uint64_t next_sample = 0;    ///< the first sample that never came
  std::uint64_t total_samples = 0;  ///< samples the job has
  double waited_s = 0.0;            ///< seconds without a chunk before the run was given up
};

struct RunMetrics
{
  std::string job_name;
  std::string job_placement;  ///< JobPlacement::yaml() of a placed job (cam.offset_m, rotation_deg, centre); "": none
  std::uint64_t samples = 0;
  std::uint64_t dropped_samples = 0;  ///< samples missing from the stream (gaps between chunks, the lost tail)
  bool complete = true;               ///< false: the stream stopped before the job's end (stream_gap)
  StreamGap stream_gap;               ///< where, when !complete
  double duration_s = 0.0;            ///< samples · Ts
  double laser_on_time_s = 0.0;
  double commanded_energy_j = 0.0;  ///< Σ P·Ts
  double deposited_energy_j = 0.0;  ///< Σ map · pixel²
  double energy_outside_map_j = 0.0;
  double peak_energy_density_jpm2 = 0.0;
  NcProgramStats nc_program;                 ///< what the NC changed in the job (recipe cap, delays, skywriting)
  double nc_speed_cap_mps = 0.0;             ///< cap on every polyline's speed (infinity: none) [m/s]
  double nc_filter_delay_s = 0.0;            ///< delay of Q_filt2 behind the command [s]
  double nc_t1_s = 0.0;                      ///< T1 (adaptive: of the fastest knot) [s]
  double nc_t2_s = 0.0;                      ///< T2 (adaptive: of the fastest knot) [s]
  std::uint64_t laser_early_samples = 0;     ///< laser on before the spot reached its mark (laser_settling.hpp)
  std::uint64_t laser_late_samples = 0;      ///< laser on after the spot left its mark
  double laser_misplaced_energy_j = 0.0;     ///< Σ P·Ts of the early and late samples [J]
  std::uint64_t laser_off_path_samples = 0;  ///< laser on, spot farther than the tolerance from every mark
  double laser_max_off_path_m = 0.0;         ///< largest distance of a laser-on spot to the marks [m]
  bool track_measured = false;               ///< false: no laser-on sample away from the marks' ends
  double track_median_jpm2 = 0.0;            ///< straight-track level: median E along the tracks [J/m²]
  double track_peak_jpm2 = 0.0;              ///< max E along the tracks, ends excluded [J/m²]
  double track_peak_to_median = 0.0;         ///< corner peak relative to the straight-track level
  double track_min_to_median = 0.0;          ///< worst dip relative to the straight-track level
  Eigen::Vector2d track_peak_point_m = Eigen::Vector2d::Zero();  ///< where the peak is [m]
  double track_mean_jpm2 = 0.0;                                  ///< mean E along the tracks, ends excluded [J/m²]
  std::uint64_t track_stride = 1;              ///< every track_stride-th laser-on sample was sampled (bounded memory)
  double corner_peak_to_track_mean = 0.0;      ///< mean over the corners of energy_peak / track mean
  double corner_peak_to_track_mean_max = 0.0;  ///< the largest of them
  std::uint64_t map_tiles = 0;                 ///< energy-map tiles the spot touched (64 × 64 pixels)
  std::uint64_t map_tiles_spilled = 0;         ///< of which written to the spill file at least once
  std::uint64_t map_spill_file_bytes = 0;      ///< disk the spill file took (16 KiB per spilled tile)
  std::size_t peak_memory_bytes =
      0;  ///< the energy stage's data at its largest: resident tiles and directory, path, index, grids, track [bytes]
  LayerQualityReport quality;           ///< contour errors, fill rate, angle errors, speed, layer time
  bool thermal_enabled = false;         ///< the thermal view ran (thermal.enabled)
  std::uint64_t thermal_samples = 0;    ///< samples of its time window
  MeltPoolStats thermal_melt_pool;      ///< melt-pool length, width and peak temperature
  ThermalEnergy thermal_energy;         ///< its energy books [J]
  double thermal_melted_area_m2 = 0.0;  ///< cells melted at least once [m²]
  std::vector<CornerReport> corners;
  /// Questionable but possible settings of the run (run_plan.hpp), one sentence each; written to
  /// metrics.yaml only when there is one.
  std::vector<std::string> warnings;
};

/// \brief Closed forms of NC §3.2–3.3 (SPEC §2) for a corner of direction change γ at speed V through
/// two box filters in series, T1 ≥ T2 (swapped if given the other way; the cascade commutes):
/// \f[ V_{f,min} = V\,|\cos(\gamma/2)|, \qquad e_c = 2 V A(T_t/2)\,|\sin(\gamma/2)|
///     = V\,\frac{T_2^2 + 3 T_1^2}{12\,T_1}\,|\sin(\gamma/2)| \f]
/// with A the integral of the cascade's area function and T_t = T1 + T2 (e_c = 0 without filter).
CornerPathStats theoreticalCorner(double speed_mps, double angle_rad, double t1_s, double t2_s);

/// \brief Streams the spot chunks and keeps, per corner, the speed minimum and the distance
/// to the corner within the corner's time window (bounded memory whatever the job length).
///
/// Sample n (time t_n = n·Ts) of the setpoint path belongs to corner c's window if
/// t_n − setpoint_delay ∈ [time_s − window_in_s, time_s + window_out_s] (actual path: actual_delay).
/// - min_speed_mps: minimum over the window's samples of |p_{n+1} − p_{n−1}| / (2·Ts);
/// - max_contour_error_m: minimum distance from the corner point to the polyline segments
///   p_n → p_{n+1} whose time interval [t_n, t_{n+1}] (minus the delay) meets the window
///   (point-to-segment distance, exact), i.e. NC's contour error at the corner (SPEC §5 (a)).
/// NaN means no data: no sample with both neighbours in the window (speed), or no segment meeting it
/// (distance), e.g. when the stream ended early or the window is shorter than Ts.
/// Stream anomalies: samples with an index already seen are skipped; the path is not joined
/// across a gap (no segment, no central difference spans it).
/// Each sample is checked only against the corners whose window can hold it (moving index over
/// the corners sorted by time): O(samples + corners) for jobs whose windows do not overlap.
class CornerTracker
{
public:
  /// \param[in] corners          corners of the job (any order; reports() keeps this order)
  /// \param[in] setpoint_delay_s delay of the setpoint path behind the ideal timeline [s]
  /// \param[in] actual_delay_s   delay of the actual path behind the ideal timeline [s]
  CornerTracker(std::vector<Corner> corners, double setpoint_delay_s, double actual_delay_s);
  void process(const SpotChunk& chunk);
  /// \brief Per corner: the measured setpoint and actual figures and theoreticalCorner(V, γ, T1, T2).
  std::vector<CornerReport> reports(double t1_s, double t2_s) const;

private:
  /// \brief The running figures of one path (setpoint or actual).
  struct Track
  {
    double delay_s = 0.0;
    Eigen::Vector2d SpotSample::*position = nullptr;  ///< which field of SpotSample is this path
    std::size_t lo = 0;                               ///< sorted corners before lo are closed
    std::vector<CornerPathStats> stats;               ///< by sorted position; +inf until touched
  };
  void advance(Track& track, std::uint64_t index, const SpotSample& sample);

  std::vector<Corner> corners_;          ///< as given
  std::vector<std::size_t> order_;       ///< corners_ indices sorted by time_s (stable)
  std::vector<double> start_s_, end_s_;  ///< windows, sorted order [s]
  std::vector<double> max_end_s_;        ///< prefix max of end_s_ [s]
  std::vector<double> min_start_s_;      ///< suffix min of start_s_ [s]
  Track setpoint_, actual_;
  int history_ = 0;     ///< valid entries of prev_ (0..2), contiguous indices
  SpotSample prev_[2];  ///< prev_[1]: the last sample taken, prev_[0]: the one before
  ChunkSequencer sequence_;
  double period_s_ = 0.0;
};

/// \brief Stream counters: samples, gaps, laser time and commanded energy.
///
/// dropped() counts stream anomalies, in samples: the samples missing at a gap (a chunk starting
/// beyond the expected next index; the stream is expected to start at index 0), plus the samples
/// of a chunk that overlap indices already counted (duplicates, late or reordered chunks), which are
/// discarded. So a chunk that arrives late after its successor counts twice: once as the gap, once
/// as discarded. samples(), laserOnTime() and commandedEnergy() cover the accepted samples only.
class StreamCounter
{
public:
  void reset();
  void process(const SpotChunk& chunk);
  std::uint64_t samples() const { return sequence_.taken(); }
  std::uint64_t dropped() const { return sequence_.missing() + sequence_.repeated(); }
  double laserOnTime() const { return laser_on_s_; }    ///< Σ Ts over samples with power > 0 [s]
  double commandedEnergy() const { return energy_j_; }  ///< Σ P·Ts [J]
  double period() const { return period_s_; }           ///< Ts of the last chunk [s]

private:
  ChunkSequencer sequence_;
  double laser_on_s_ = 0.0, energy_j_ = 0.0, period_s_ = 0.0;
};
}  // namespace scanhead
