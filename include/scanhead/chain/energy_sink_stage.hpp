/// \file energy_sink_stage.hpp
/// \brief The energy stage behind the Stage interface (chain_stages.hpp): the last stage of the
/// chain, in its own header so that the stages before it do not depend on the energy stage.
#pragma once

#include <cstdint>
#include <memory>

#include "scanhead/chain/chain_config.hpp"
#include "scanhead/chain/chain_stages.hpp"
#include "scanhead/chain/energy_stage.hpp"
#include "scanhead/common/stage.hpp"

namespace scanhead
{
/// \brief The energy stage of a whole run: each reset starts a new EnergyStage on the job and
/// its plan; process() returns the samples taken so far; finish() the run's metrics.
class EnergySinkStage final : public Stage<PlannedJob, SpotChunk, std::uint64_t, RunMetrics>
{
public:
  explicit EnergySinkStage(const ChainConfig& config)
    : config_(config)
  {
  }
  void reset(const PlannedJob& job) override { stage_ = std::make_unique<EnergyStage>(config_, job.job, job.plan); }
  /// \pre reset() was called (throws std::logic_error otherwise)
  std::uint64_t process(const SpotChunk& chunk) override;
  /// \pre reset() was called (throws std::logic_error otherwise)
  RunMetrics finish() override;
  /// \brief The energy stage of the last job (map, traces). \pre reset() was called
  const EnergyStage& stage() const;
  /// \brief Hands over the energy stage of the last job (e.g. to keep showing it while the next
  /// job runs); process() and finish() need a reset() after this.
  std::unique_ptr<EnergyStage> release() { return std::move(stage_); }

private:
  ChainConfig config_;
  std::unique_ptr<EnergyStage> stage_;
};
}  // namespace scanhead
