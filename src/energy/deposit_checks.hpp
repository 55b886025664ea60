/// \file deposit_checks.hpp
/// \brief The checks both deposit methods make on a segment of the spot path (private to src/energy):
/// one wording of each error, whatever the method.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <sstream>

#include "scanhead/common/errors.hpp"
#include "scanhead/energy/energy_config.hpp"
#include "scanhead/energy/spot_footprint.hpp"

namespace scanhead::energy_detail
{
constexpr double kMaxSubsteps = 1.0e8;       // a longer segment is garbage, not a path
constexpr double kMaxStencilRadius = 1.0e4;  // pixels: a footprint this large is a configuration error

/// \throws NumericalError if the segment from → to (length \p length) is not finite
inline void requireFiniteSegment(const Eigen::Vector2d& from, const Eigen::Vector2d& to, double length)
{
  if (!from.allFinite() || !std::isfinite(length))
  {
    std::ostringstream msg;
    msg << "energy: non-finite spot position (" << from.x() << ", " << from.y() << ") -> (" << to.x() << ", " << to.y()
        << ") m while the laser is on";
    throw NumericalError(msg.str());
  }
}

/// \brief m = max(1, ceil(length / (max_substep_radii·w))): the sub-steps of the sampled method, and the plausibility
/// measure of a move for both methods.
/// \throws NumericalError if m > 1e8 (a move of ~1.7 km with the default settings: garbage, not a path)
inline double substepsOf(double length, const EnergyConfig& config, const SpotFootprint& fp)
{
  const double steps = std::max(1.0, std::ceil(length / (config.max_substep_radii * fp.radius_m)));
  if (steps > kMaxSubsteps)
  {
    std::ostringstream msg;
    msg << "energy: spot moved " << length << " m in one sample with the laser on (" << steps
        << " sub-steps): implausible";
    throw NumericalError(msg.str());
  }
  return steps;
}

/// \brief Stencil radius [pixels] of the point-sampled spot: every pixel centre within R = truncation_radii·w_major of
/// a point of the centre pixel lies within R/p + sqrt(1/2) of the centre pixel's centre; rounded up to 1/8 pixel.
/// \throws ConfigError if it exceeds 1e4 pixels (a defocused spot on too fine a map)
inline double stencilRadius(const EnergyConfig& config, const SpotFootprint& fp, double p)
{
  const double rs = std::ceil(8.0 * (config.truncation_radii * fp.major_radius_m / p + std::sqrt(0.5))) / 8.0;
  if (rs > kMaxStencilRadius)
  {
    std::ostringstream msg;
    msg << "energy: the footprint (radius " << fp.major_radius_m << " m, defocus " << fp.defocus_m << " m) spans " << rs
        << " pixels of energy.pixel_m = " << p << " m: raise energy.pixel_m";
    throw ConfigError(msg.str());
  }
  return rs;
}
}  // namespace scanhead::energy_detail
