/// \file polyline_fixture.hpp
/// \brief The polyline builder the core tests share.
#pragma once

#include <utility>
#include <vector>

#include "scanhead/core/scan_job.hpp"

namespace scanhead::test_support
{
/// \brief A polyline of \p type at \p speed [m/s] and \p power [W] through \p points [m].
inline Polyline line(PolylineType type, double speed, double power, std::vector<Eigen::Vector2d> points)
{
  Polyline p;
  p.type = type;
  p.speed_mps = speed;
  p.power_w = power;
  p.points = std::move(points);
  return p;
}
}  // namespace scanhead::test_support
