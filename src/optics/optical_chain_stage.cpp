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
  out.samples.reserve(n);
  // Both traces in blocks of kBlock rays, structure of arrays (OpticalModel::traceBlock:
  // bit-identical to trace() ray by ray); a failed ray is traced again alone for its error. Each
  // sample is then written once, whole (no default construction first).
  constexpr std::size_t kBlock = 256;
  double a_x[kBlock], a_y[kBlock], s_x[kBlock], s_y[kBlock], d_x[kBlock], d_y[kBlock], d_z[kBlock];
  double qa_x[kBlock], qa_y[kBlock], qs_x[kBlock], qs_y[kBlock];
  for (std::size_t begin = 0; begin < n; begin += kBlock)
  {
    const std::size_t m = std::min(kBlock, n - begin);
    const JointSample* const actual = joints.samples.data() + begin;
    const SetpointSample* const commanded = setpoint.samples.data() + begin;
    for (std::size_t i = 0; i < m; ++i)
    {
      qa_x[i] = actual[i].position.x();
      qa_y[i] = actual[i].position.y();
      qs_x[i] = commanded[i].position.x();
      qs_y[i] = commanded[i].position.y();
    }
    if (optics_.traceBlock(m, qa_x, qa_y, a_x, a_y, d_x, d_y, d_z) > 0)
    {
      rethrowFirstFailure(optics_, m, qa_x, qa_y, a_x);
    }
    if (optics_.traceBlock(m, qs_x, qs_y, s_x, s_y) > 0)
    {
      rethrowFirstFailure(optics_, m, qs_x, qs_y, s_x);
    }
    const LaserSample* const power = laser.samples.data() + begin;
    for (std::size_t i = 0; i < m; ++i)
    {
      out.samples.push_back(SpotSample{Eigen::Vector2d(s_x[i], s_y[i]), Eigen::Vector2d(a_x[i], a_y[i]),
                                       Eigen::Vector3d(d_x[i], d_y[i], d_z[i]),
                                       Eigen::Vector2d(qs_x[i] - qa_x[i], qs_y[i] - qa_y[i]), power[i].power_w});
    }
  }
  return out;
}
}  // namespace scanhead
