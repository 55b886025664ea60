/// \file batch_chain.hpp
/// \brief The whole chain in one process: NC → servo → optics → energy, chunk by chunk.
#pragma once

#include <functional>
#include <memory>

#include "scanhead/chain/chain_config.hpp"
#include "scanhead/chain/chain_stages.hpp"
#include "scanhead/chain/energy_sink_stage.hpp"
#include "scanhead/chain/run_plan.hpp"
#include "scanhead/common/package_path.hpp"
#include "scanhead/optics/optical_model.hpp"
#include "scanhead/optics/optics_loading.hpp"

namespace scanhead
{
/// \brief Called after each chunk with the samples done and the job's total.
using ProgressCallback = std::function<void(std::uint64_t done, std::uint64_t total)>;
/// \brief Receives each warning of a run (a questionable setting), once.
using WarningSink = std::function<void(const std::string& warning)>;

/// \brief The stages of chain_stages.hpp, driven in one process: reset each for the job (the NC
/// first: its plan resets the others), then chunk by chunk NC → servo → optics → energy.
///
/// With stream.threads = 2 (the default) the chain is a two-stage pipeline: NC, servo and optics
/// run on a second thread and hand their spot chunks to the energy stage (on the calling thread)
/// through a queue of a few chunks, so memory stays bounded; each side takes the chunks in stream
/// order, so the results are bit-identical to stream.threads = 1 (everything on the calling thread).
class BatchChain
{
public:
  /// \param[in] optics must outlive this object
  /// \throws ConfigError (what the stages throw; out of memory building them, naming the stage)
  BatchChain(const ChainConfig& config, const OpticalModel& optics);

  /// \brief Runs a validated job to the end. The energy stage stays available for the map and traces.
  /// \p progress is called on the calling thread. An exception of any stage stops both threads and
  /// reaches the caller.
  ///
  /// First, before any allocation that grows with the job, the run is planned (planRun) and refused
  /// beyond config.limits (enforceRunLimits): ConfigError naming the cause and the key to raise; a
  /// physically impossible speed or power is an error too. The plan's warnings go to the warning
  /// sink (stderr unless setWarningSink) and into the metrics (RunMetrics::warnings). Should a
  /// stage still run out of memory, std::bad_alloc becomes a ConfigError naming the stage, the
  /// plan's estimate and the settings that size it.
  RunMetrics run(const Job& job, const ProgressCallback& progress = {});
  /// \brief run() with the plan the caller already made and enforced (a tool that plans before it
  /// starts anything else), so the job is not planned twice.
  /// \pre \p plan is planRun(config, job, optics) of this chain's config and optics, and passed
  /// enforceRunLimits
  RunMetrics run(const Job& job, const RunPlan& plan, const ProgressCallback& progress = {});

  /// \brief The plan of the last run() (planned even when it was refused).
  const RunPlan& plan() const { return plan_; }
  /// \brief Where run() sends the plan's warnings (default: "warning: <text>" lines on stderr).
  void setWarningSink(WarningSink sink) { warn_ = std::move(sink); }

  const EnergyStage& energy() const { return energy_.stage(); }
  const NcInterpolator& nc() const { return nc_.interpolator(); }
  std::uint64_t totalSamples() const { return nc_.interpolator().totalSamples(); }

private:
  SpotChunk nextSpotChunk();  ///< NC → servo → optics for the next chunk

  RunMetrics runPlanned(const Job& job, const ProgressCallback& progress);

  ChainConfig config_;
  const OpticalModel& optics_model_;
  RunPlan plan_;
  WarningSink warn_;
  NcStage nc_;
  ServoStage servo_;
  OpticsStage optics_;
  EnergySinkStage energy_;
};

}  // namespace scanhead
