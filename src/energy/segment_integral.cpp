/// \file segment_integral.cpp
/// \brief The closed form of the swept Gaussian spot.
#include "scanhead/energy/segment_integral.hpp"

#include <cmath>

namespace scanhead
{
SegmentIntegral::SegmentIntegral(const SpotFootprint& fp, const Eigen::Vector2d& d)
  : qxx(fp.qxx)
  , qxy(fp.qxy)
  , qyy(fp.qyy)
{
  const double det = qxx * qyy - qxy * qxy;
  const Eigen::Vector2d qd(qxx * d.x() + qxy * d.y(), qxy * d.x() + qyy * d.y());
  const double a = d.dot(qd);
  sqrt_a = std::sqrt(a);
  if (!(sqrt_a >= kStationaryLimit))
  {
    stationary = true;
    centre = 0.5 * d;
    amplitude = std::sqrt(det) / M_PI;
    return;
  }
  g = qd / sqrt_a;
  const double length = d.norm();
  const Eigen::Vector2d normal(-d.y() / length, d.x() / length);
  m = normal * std::sqrt(det * length * length / a);
  amplitude = std::sqrt(det) / M_PI * 0.5 * std::sqrt(M_PI / a);
}

double SegmentIntegral::weight(const Eigen::Vector2d& r) const
{
  if (stationary)
  {
    const Eigen::Vector2d x = r - centre;
    return std::exp(-(qxx * x.x() * x.x() + 2.0 * qxy * x.x() * x.y() + qyy * x.y() * x.y()));
  }
  const double s = m.dot(r), u = g.dot(r);
  return std::exp(-s * s) * (std::erf(sqrt_a - u) + std::erf(u));
}
}  // namespace scanhead
