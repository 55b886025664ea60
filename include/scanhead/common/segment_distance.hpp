/// \file segment_distance.hpp
/// \brief Exact distance from a point to a segment in the plane (contour errors, shapes, laser checks).
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>

namespace scanhead
{
/// \brief pointSegmentDistance() squared: the distance is its square root, bit for bit (Eigen's norm() is the root of
/// squaredNorm()), so the nearer of two segments takes one root, not two (√ is monotone and correctly rounded).
inline double pointSegmentDistance2(const Eigen::Vector2d& p, const Eigen::Vector2d& a, const Eigen::Vector2d& b)
{
  const Eigen::Vector2d ab = b - a;
  const double len2 = ab.squaredNorm();
  const double t = len2 > 0.0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
  return (a + t * ab - p).squaredNorm();
}

/// \brief Distance from \p p to the segment [a, b] (to a when a = b).
inline double pointSegmentDistance(const Eigen::Vector2d& p, const Eigen::Vector2d& a, const Eigen::Vector2d& b)
{
  return std::sqrt(pointSegmentDistance2(p, a, b));
}
}  // namespace scanhead
