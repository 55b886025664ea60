#include "scanhead/chain/energy_sink_stage.hpp"

#include <stdexcept>

namespace scanhead
{
std::uint64_t EnergySinkStage::process(const SpotChunk& chunk)
{
  if (!stage_)
    throw std::logic_error("EnergySinkStage::process() before reset()");
  stage_->process(chunk);
  return stage_->samplesSeen();
}

RunMetrics EnergySinkStage::finish()
{
  if (!stage_)
    throw std::logic_error("EnergySinkStage::finish() before reset()");
  return stage_->finish();
}

const EnergyStage& EnergySinkStage::stage() const
{
  if (!stage_)
    throw std::logic_error("EnergySinkStage::stage() before reset()");
  return *stage_;
}
}  // namespace scanhead
