#include "scanhead/optics/optical_chain_stage.hpp"

#include <stdexcept>
#include <string>

namespace scanhead
{
SpotChunk OpticalChainStage::process(const SetpointChunk& setpoint, const JointChunk& joints,
                                     const LaserChunk& laser) const
{
  const std::size_t n = setpoint.samples.size();
  if (joints.first_index != setpoint.first_index || laser.first_index != setpoint.first_index ||
      joints.samples.size() != n || laser.samples.size() != n || joints.period_s != setpoint.period_s ||
      laser.period_s != setpoint.period_s)
    throw std::invalid_argument("optical chain: setpoint, joint and laser chunks are not aligned (first index " +
                                std::to_string(setpoint.first_index) + ", " + std::to_string(joints.first_index) +
                                ", " + std::to_string(laser.first_index) + ")");
  SpotChunk out;
  out.first_index = setpoint.first_index;
  out.period_s = setpoint.period_s;
  out.samples.resize(n);
  for (std::size_t k = 0; k < n; ++k)
  {
    SpotSample& s = out.samples[k];
    const OpticalModel::Ray ray = optics_.trace(joints.samples[k].position);
    s.actual = ray.spot;
    s.direction = ray.direction;
    s.setpoint = optics_.spot(setpoint.samples[k].position);
    s.angle_error = setpoint.samples[k].position - joints.samples[k].position;
    s.power_w = laser.samples[k].power_w;
  }
  return out;
}
}  // namespace scanhead
