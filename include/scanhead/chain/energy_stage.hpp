/// \file energy_stage.hpp
/// \brief The last stage: spot stream in; energy map, corner figures, counters and plot traces out.
/// The node and the batch runner both run this class, so they report the same metrics.
#pragma once

#include <memory>

#include "scanhead/chain/chain_config.hpp"
#include "scanhead/chain/trace_recorder.hpp"
#include "scanhead/common/side_thread.hpp"
#include "scanhead/energy/energy_accumulator.hpp"
#include "scanhead/job/scan_job.hpp"
#include "scanhead/metrics/laser_placement.hpp"
#include "scanhead/metrics/laser_settling.hpp"
#include "scanhead/metrics/layer_quality.hpp"
#include "scanhead/metrics/run_metrics.hpp"
#include "scanhead/nc/nc_plan.hpp"
#include "scanhead/nc/nc_stats.hpp"
#include "scanhead/report/energy_exports.hpp"
#include "scanhead/thermal/thermal_layer.hpp"

namespace scanhead
{
/// \brief Map area for a job: the bounding box of all its points grown by energy.map_margin_m.
void jobMapBounds(const Job& job, double margin_m, Eigen::Vector2d& min_corner, Eigen::Vector2d& max_corner);

class EnergyStage
{
public:
  /// \param[in] job  the job as given (map bounds)
  /// \param[in] plan the NC's plan of \p job (NcInterpolator::plan(), or received with the job): its
  ///                 program gives the corners' times and the laser windows, its delays where the
  ///                 actual path is, total_samples the plot decimation. Copied where needed.
  /// \throws std::invalid_argument if the plan has no servo delay (an NC built without the servo model)
  EnergyStage(const ChainConfig& config, const Job& job, const NcPlan& plan);
  /// \brief Deposits the chunk's energy and feeds every tracker; with stream.threads = 2 the trackers
  /// run on a second thread while the map is written (they share only the read-only chunk), joined
  /// before returning.
  void process(const SpotChunk& chunk);
  /// \brief Ends the stream and returns the run's metrics (with stream.threads = 2, the nearest-path
  /// pass on a second thread while the map is read once: the track's energy, the corner peaks and mapViews()).
  /// The last call: it frees the data only its figures read (the track samples, the actual path, a spilled map's
  /// resident tiles).
  RunMetrics finish();

  /// \brief The energy map: complete after finish() (with stream.threads = 2 the strokes of the last chunk processed
  /// are added during the next one).
  const TiledEnergyMap& map() const { return accumulator_.map(); }
  /// \brief The overview and crops the results show (report/energy_exports.hpp), read from the map once: by
  /// finish(), or at the first call before it (a map still growing; read again after finish()). Not thread-safe.
  std::shared_ptr<const EnergyMapViews> mapViews() const;
  const TraceRecorder& trace() const { return trace_; }
  std::uint64_t samplesSeen() const { return counter_.samples(); }
  /// \brief The thermal view, or nullptr when thermal.enabled is false.
  const ThermalLayer* thermal() const { return thermal_.get(); }

private:
  void keepTrack(const SpotChunk& chunk);
  void thinTrack();
  void feedThermal(const SpotChunk& chunk);

  ChainConfig config_;
  std::string job_name_;
  std::string job_placement_;  ///< RunMetrics::job_placement
  double actual_delay_s_;      ///< the actual path behind the ideal timeline: filter + servo delay [s]
  EnergyAccumulator accumulator_;
  CornerTracker corners_;
  LaserSettlingCheck settling_;
  LaserPlacement placement_;
  std::vector<SpotSample>
      track_;                     ///< every track_stride_-th laser-on sample, and one laser-off sample after each burst
  std::uint64_t track_seen_ = 0;  ///< laser-on samples seen
  std::uint64_t track_stride_ = 1;  ///< doubles whenever track_ would exceed energy.track_max_samples
  std::size_t track_peak_bytes_ = 0;
  std::vector<Eigen::Vector2d> mark_ends_;  ///< first and last points of the marks: not track interior
  StreamCounter counter_;
  TraceRecorder trace_;
  NcStats nc_stats_;  ///< the plan's figures (the per-sample ones stay with the NC)
  LayerQuality quality_;
  std::unique_ptr<ThermalLayer> thermal_;  ///< optional (thermal.enabled)
  std::uint64_t thermal_samples_ = 0;      ///< samples given to it
  std::unique_ptr<SideThread> side_;       ///< runs the trackers beside the map (stream.threads = 2)
  std::vector<MapRegion> export_crops_;    ///< the crops of the results (exportCrops; finish() adds the worst corner)
  mutable std::shared_ptr<const EnergyMapViews> views_;  ///< read once, by finish() or mapViews()
};
}  // namespace scanhead
