/// \file layer_quality.hpp
/// \brief The quality figures of a layer (SPEC §5, THESIS §2.5.3–2.6): contour error by both
/// definitions, split by kind of commanded point; fill rate; per-axis angle-error histograms; the
/// speed profile along the marks; the layer time.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <memory>
#include <vector>

#include "scanhead/common/chunk.hpp"
#include "scanhead/common/chunk_sequencer.hpp"
#include "scanhead/common/histogram.hpp"
#include "scanhead/energy/energy_config.hpp"
#include "scanhead/job/path_timeline.hpp"
#include "scanhead/job/scan_job.hpp"
#include "scanhead/metrics/contour_error.hpp"
#include "scanhead/metrics/fill_rate.hpp"

namespace scanhead
{
class NearestPathIndex;

/// \brief Contour errors of one definition, by kind of commanded point.
struct ContourErrorSplit
{
  ContourErrorStats mark;     ///< every point of a MARK segment (laser commanded on)
  ContourErrorStats contour;  ///< the marks of contour polylines (THESIS: the shares it reports)
  ContourErrorStats hatch;    ///< the other marks (hatch, or role unspecified)
  ContourErrorStats jump;     ///< jumps, skywriting moves and laser-off holds
};

struct LayerQualityReport
{
  double layer_time_s = 0.0;           ///< the NC program's duration, holds included (THESIS's layer time) [s]
  double lag_s = 0.0;                  ///< actual path behind the command, for the same-instant pairing [s]
  double window_s = 0.0;               ///< the same-instant search half-width used [s]
  std::uint64_t commanded_points = 0;  ///< samples of the program (t < layer time)
  std::uint64_t unmatched_points = 0;  ///< commanded points whose same-instant sample never came (stream gaps, end)
  ContourErrorSplit same_instant;      ///< definition (b), THESIS §2.5.3.1
  bool nearest_measured = false;       ///< false: more samples than energy.contour_max_samples
  ContourErrorSplit nearest_path;      ///< definition (a), NC: distance to the whole actual path
  std::uint64_t fill_cells_to_fill = 0;
  std::uint64_t fill_cells_reached = 0;
  double fill_rate = 0.0;                 ///< reached / to fill (NaN: nothing to fill)
  std::uint64_t fill_points_outside = 0;  ///< points off the fill grid (counted, not silently dropped)
  double fill_pitch_m = 0.0;              ///< cell side = spot diameter [m]
  /// Q_filt2 − Q_exp over the program [rad], 2 µrad bins (2.8 µm at the plane) over ±250 µrad (±0.35 mm);
  /// beyond, counted as under/overflow
  Histogram angle_error_x{-250e-6, 250e-6, 250};
  Histogram angle_error_y{-250e-6, 250e-6, 250};
  Histogram mark_speed_ratio{0.0, 1.5, 150};  ///< actual speed / programmed speed, laser-on mark samples
  double mark_speed_mean_ratio = NAN;         ///< mean of the ratio over laser-on mark samples (NaN: none)
  std::size_t memory_bytes = 0;  ///< largest memory of these trackers (path, index, grids, timeline copy) [bytes]
};

/// \brief Streams the spot chunks against the NC program's ideal timeline and measures the layer.
///
/// Commanded point k (k·Ts < layer time) is the program's position at t_k = k·Ts; its kind is its
/// segment's (mark or not; contour if its job polyline has role Contour). The actual sample of the
/// same instant is j = k + L, L = round(lag/Ts), lag = energy.contour_lag_s or, when < 0, the
/// filter delay plus the servo's low-frequency delay (as the corner tracker).
/// - same instant (b), THESIS §2.5.3.1 after Duong et al. 2016: among the actual samples
///   j ∈ [k + L − N, k + L + N] (N = energy.same_instant_window_s / Ts), the one nearest to c_k (the
///   least following error; ties: the earliest), then the min distance from c_k to its adjacent
///   segments [p_{j−1}, p_j], [p_j, p_{j+1}] (exact, in double; streaming, O(N) per point). N = 0
///   is the strict same instant; N > 0 absorbs what the lag L misses (friction offsets along the
///   track, axis lags), as the THESIS's search for the least following error does;
/// - nearest path (a): min distance from c_k to every segment of the whole actual path (float
///   storage relative to the map origin: 3e-8 m resolution at 0.35 m), at finish() through
///   NearestPathIndex, the strict same-instant distance as upper bound (on two threads with
///   finish(2), the same figures); jobs with more than
///   energy.contour_max_samples samples skip it (16 B per sample would not stay bounded);
/// - fill rate: FillRateGrid of pitch = spot diameter; to fill: the commanded hatch marks; reached:
///   the laser-on actual spot while its same-instant command is a hatch mark;
/// - angle errors: every sample with t_k < layer time; speed ratio: |p_j − p_{j−1}|/Ts over the
///   programmed speed of command k, for laser-on samples whose command is a mark (not a dwell).
/// The path is not joined across a stream gap; samples already seen are skipped.
class LayerQuality
{
public:
  /// \param[in] timeline the NC program's timeline (copied)
  /// \param[in] job      the job (roles of the polylines)
  /// \param[in] lag_s    ≥ 0 [s]
  /// \param[in] min_corner, max_corner  fill grid and path origin [m]
  LayerQuality(const EnergyConfig& config, const PathTimeline& timeline, const Job& job, double lag_s,
               std::uint64_t total_samples, const Eigen::Vector2d& min_corner, const Eigen::Vector2d& max_corner);
  ~LayerQuality();
  void process(const SpotChunk& chunk);
  /// \brief Ends the stream: the last same-instant points, the nearest-path pass, the report. The last call: it frees
  /// the actual path.
  /// \param[in] threads 2: the nearest-path index built and queried on two threads (the same report, bit for bit)
  LayerQualityReport finish(unsigned threads = 1);

private:
  enum class Kind : std::uint8_t
  {
    None,  ///< after the program (tail)
    Contour,
    Hatch,
    Jump
  };
  struct Command
  {
    Eigen::Vector2d point = Eigen::Vector2d::Zero();
    Kind kind = Kind::None;
    double speed_mps = 0.0;  ///< programmed speed (0 on dwells and holds)
  };
  Command commandAt(std::uint64_t k, PathTimeline::Cursor& cursor) const;
  /// \brief commandAt(k), from the cache of the last commands when it holds k.
  const Command& cachedCommand(std::uint64_t k, PathTimeline::Cursor& cursor);
  void sameInstant(std::uint64_t k);
  void nearestPathPass(const NearestPathIndex& index, unsigned threads);
  void unmatched(std::uint64_t k);
  Eigen::Vector2d held(std::uint64_t index) const;
  void hold(std::uint64_t index, const Eigen::Vector2d& p);
  static void addTo(ContourErrorSplit& split, Kind kind, double error_m);

  EnergyConfig config_;
  PathTimeline timeline_;  ///< a copy: the NC that made it may not outlive the stage (the node's)
  std::vector<bool> contour_polyline_;
  std::uint64_t lag_samples_ = 0;
  std::uint64_t program_samples_ = 0;  ///< commanded points: k with k·Ts < layer time
  double period_s_ = 0.0;
  LayerQualityReport report_;
  FillRateGrid fill_;
  bool keep_path_ = false;
  PathPoints path_;
  bool path_gapped_ = false;
  PathTimeline::Cursor command_cursor_, lagged_cursor_;
  // The last ring_size_ = 2N + 3 actual samples, [ring_first_, next_index_), sample i's x at
  // ring_x_[i & ring_mask_] and again at ring_mask_ + 1 places further (a mirror: any run of held
  // samples is contiguous, for the vectorised search), y likewise.
  std::vector<double> ring_x_, ring_y_;
  std::uint64_t ring_size_ = 0;
  std::uint64_t ring_mask_ = 0;  ///< storage 2^b − 1 ≥ ring_size_
  // Command k is needed twice (the lagged command of sample k + L, then its same-instant pairing
  // N + 1 samples later): the last ones, command k at command_cache_[k & mask].
  std::vector<Command> command_cache_;
  std::vector<std::uint64_t> command_cache_k_;  ///< which k each entry holds (UINT64_MAX: none)
  std::uint64_t ring_first_ = 0;
  std::uint64_t next_index_ = 0;
  bool started_ = false;
  ChunkSequencer sequence_;           ///< which samples are new, where the stream broke
  std::uint64_t window_samples_ = 0;  ///< N: the same-instant search half-width [samples]
  std::uint64_t next_command_ = 0;    ///< first commanded point not evaluated yet by (b)
  double speed_ratio_sum_ = 0.0, speed_samples_ = 0.0;
};
}  // namespace scanhead
