#include "scanhead/chain/batch_chain.hpp"

namespace scanhead
{
BatchChain::BatchChain(const ChainConfig& config, const OpticalModel& optics)
  : config_(config)
  , nc_(config, optics)
  , servo_(config.servo)
  , optics_(optics)
  , energy_(config)
{
}

RunMetrics BatchChain::run(const Job& job, const ProgressCallback& progress)
{
  nc_.reset(job);
  const PlannedJob planned{job, nc_.plan()};
  servo_.reset({nc_.plan().period_s});
  optics_.reset({});
  energy_.reset(planned);
  while (!nc_.done())
  {
    const NcOutput nc = nc_.process(config_.stream.chunk_samples);
    const JointChunk joints = servo_.process(nc.setpoint);
    energy_.process(optics_.process({nc.setpoint, joints, nc.laser}));
    if (progress)
      progress(nc.setpoint.endIndex(), nc_.plan().total_samples);
  }
  return energy_.finish();
}
}  // namespace scanhead
