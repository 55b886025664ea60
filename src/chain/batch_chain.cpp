#include "scanhead/chain/batch_chain.hpp"

namespace scanhead
{
BatchChain::BatchChain(const ChainConfig& config, const OpticalModel& optics)
  : config_(config), optics_(optics), nc_(config.nc, resolveRecipe(config.recipe), optics, &config.servo), servo_(config.servo, config.nc.period_s), optical_stage_(optics)
{
}

RunMetrics BatchChain::run(const Job& job, const ProgressCallback& progress)
{
  nc_.start(job);
  energy_ = std::make_unique<EnergyStage>(config_, job, nc_.plan());
  while (!nc_.done())
  {
    const NcOutput nc = nc_.process(config_.stream.chunk_samples);
    if (nc.setpoint.first_index == 0 && !nc.setpoint.samples.empty())
      servo_.reset(nc.setpoint.samples.front().position);  // at rest where the job starts
    const JointChunk joints = servo_.process(nc.setpoint);
    energy_->process(optical_stage_.process(nc.setpoint, joints, nc.laser));
    if (progress)
      progress(nc.setpoint.endIndex(), nc_.totalSamples());
  }
  return energy_->finish();
}
}  // namespace scanhead
