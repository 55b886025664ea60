/// \file energy_stage.hpp
/// \brief The last stage: spot stream in; energy map, corner figures, counters and plot traces out.
/// The node and the batch runner both run this class, so they report the same metrics.
#pragma once

#include <memory>

#include "scanhead/core/chain_config.hpp"
#include "scanhead/core/energy_map.hpp"
#include "scanhead/core/run_metrics.hpp"
#include "scanhead/core/scan_job.hpp"
#include "scanhead/core/trace_recorder.hpp"

namespace scanhead
{
/// \brief Map area for a job: the bounding box of all its points grown by energy.map_margin_m.
void jobMapBounds(const Job& job, double margin_m, Eigen::Vector2d& min_corner, Eigen::Vector2d& max_corner);

class EnergyStage
{
public:
  /// \param[in] total_samples the job's sample count (for the plot decimation)
  EnergyStage(const ChainConfig& config, const Job& job, std::uint64_t total_samples);
  void process(const SpotChunk& chunk);
  /// \brief Ends the stream and returns the run's metrics.
  RunMetrics finish();

  const EnergyMap& map() const { return accumulator_.map(); }
  const TraceRecorder& trace() const { return trace_; }
  std::uint64_t samplesSeen() const { return counter_.samples(); }

private:
  ChainConfig config_;
  std::string job_name_;
  EnergyAccumulator accumulator_;
  CornerTracker corners_;
  StreamCounter counter_;
  TraceRecorder trace_;
};
}  // namespace scanhead
