#include "scanhead/chain/chain_stages.hpp"

#include <stdexcept>

#include "scanhead/job/formats/job_io.hpp"
#include "scanhead/job/job_files.hpp"

namespace scanhead
{
void CamStage::reset(const std::string& argument)
{
  Job job = loadJob(argument, cam_);
  validateScanJob(job, field_half_width_m_);
  job_ = std::move(job);
}

NcStage::NcStage(const ChainConfig& config, const OpticalModel& optics)
  : nc_(config.nc, resolveRecipe(config.recipe), optics, &config.servo)
{
}

void ServoStage::reset(const ServoJob& job)
{
  servo_ = std::make_unique<GalvoServo>(config_, job.period_s);
  at_rest_pending_ = true;
}

JointChunk ServoStage::process(const SetpointChunk& setpoint)
{
  if (!servo_)
    throw std::logic_error("ServoStage::process() before reset()");
  if (at_rest_pending_ && !setpoint.samples.empty())
  {
    servo_->reset(setpoint.samples.front().position);  // at rest where the job starts
    at_rest_pending_ = false;
  }
  return servo_->process(setpoint);
}
}  // namespace scanhead
