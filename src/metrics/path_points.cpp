/// \file path_points.cpp
/// \brief The actual path as float offsets with breaks.
#include "scanhead/metrics/path_points.hpp"

#include <cmath>
#include <string>

#include "contour_error_text.hpp"
#include "scanhead/common/errors.hpp"

namespace scanhead
{
PathPoints::PathPoints(const Eigen::Vector2d& origin)
  : origin_(origin)
{
  if (!origin.allFinite())
    throw InputError("contour error: path origin " + pointText(origin) + " m is not finite");
}

void PathPoints::reserve(std::size_t points)
{
  xy_.reserve(2 * points);
  break_after_.reserve(points / 64 + 1);
}

void PathPoints::add(const Eigen::Vector2d& p)
{
  const std::size_t i = size();
  if (!p.allFinite())
    throw InputError("contour error: actual path point " + std::to_string(i) + " " + pointText(p) + " m is not finite");
  const Eigen::Vector2d u = p - origin_;
  const float fx = static_cast<float>(u.x());
  const float fy = static_cast<float>(u.y());
  if (!std::isfinite(fx) || !std::isfinite(fy))
  {
    throw InputError("contour error: actual path point " + std::to_string(i) + " " + pointText(p) +
                     " m is too far from the origin to be stored as a float offset");
  }
  if ((i & 63) == 0)
    break_after_.push_back(0);
  xy_.push_back(fx);
  xy_.push_back(fy);
}

void PathPoints::breakPath()
{
  if (empty())
    return;
  const std::size_t last = size() - 1;
  break_after_[last >> 6] |= std::uint64_t(1) << (last & 63);
}

std::size_t PathPoints::memoryBytes() const
{
  return sizeof(*this) + xy_.capacity() * sizeof(float) + break_after_.capacity() * sizeof(std::uint64_t);
}
}  // namespace scanhead
