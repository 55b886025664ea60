#include "scanhead/optics/optical_chain_stage.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "scanhead/common/errors.hpp"

namespace scanhead
{
namespace
{
/// The error trace() gives for the first ray of a block that failed (its spot is NaN).
[[noreturn]] void rethrowFirstFailure(const OpticalModel& optics, std::size_t m, const double* q_x, const double* q_y,
                                      const double* s_x)
{
  for (std::size_t i = 0; i < m; ++i)
  {
    if (std::isnan(s_x[i]))
    {
      optics.trace(Eigen::Vector2d(q_x[i], q_y[i]));  // throws NumericalError
    }
  }
  throw NumericalError("optical chain: a ray trace failed without an error");
}
}  // namespace

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
  // Both traces in blocks of kBlock rays, structure of arrays (OpticalModel::traceBlock:
  // bit-identical to trace() ray by ray); a failed ray is traced again alone for its error.
  constexpr std::size_t kBlock = 256;
  double q_x[kBlock], q_y[kBlock], s_x[kBlock], s_y[kBlock], d_x[kBlock], d_y[kBlock], d_z[kBlock];
  for (std::size_t begin = 0; begin < n; begin += kBlock)
  {
    const std::size_t m = std::min(kBlock, n - begin);
    for (std::size_t i = 0; i < m; ++i)
    {
      const Eigen::Vector2d& q = joints.samples[begin + i].position;
      q_x[i] = q.x();
      q_y[i] = q.y();
    }
    if (optics_.traceBlock(m, q_x, q_y, s_x, s_y, d_x, d_y, d_z) > 0)
    {
      rethrowFirstFailure(optics_, m, q_x, q_y, s_x);
    }
    for (std::size_t i = 0; i < m; ++i)
    {
      SpotSample& s = out.samples[begin + i];
      s.actual = Eigen::Vector2d(s_x[i], s_y[i]);
      s.direction = Eigen::Vector3d(d_x[i], d_y[i], d_z[i]);
      const Eigen::Vector2d& q = setpoint.samples[begin + i].position;
      q_x[i] = q.x();
      q_y[i] = q.y();
    }
    if (optics_.traceBlock(m, q_x, q_y, s_x, s_y) > 0)
    {
      rethrowFirstFailure(optics_, m, q_x, q_y, s_x);
    }
    for (std::size_t i = 0; i < m; ++i)
    {
      SpotSample& s = out.samples[begin + i];
      s.setpoint = Eigen::Vector2d(s_x[i], s_y[i]);
      s.angle_error = setpoint.samples[begin + i].position - joints.samples[begin + i].position;
      s.power_w = laser.samples[begin + i].power_w;
    }
  }
  return out;
}
}  // namespace scanhead
