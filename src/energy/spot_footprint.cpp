/// \file spot_footprint.cpp
/// \brief The spot's quadratic form on the plane from the beam direction and the defocus.
#include "scanhead/energy/spot_footprint.hpp"

#include <cmath>
#include <sstream>

#include "scanhead/common/errors.hpp"

namespace scanhead
{
SpotFootprint spotFootprint(const EnergyConfig& config, const Eigen::Vector3d& direction)
{
  const double norm = direction.norm();
  if (!direction.allFinite() || !(std::abs(direction.z()) > 1e-6 * norm))
  {
    std::ostringstream msg;
    msg << "energy: beam direction (" << direction.x() << ", " << direction.y() << ", " << direction.z()
        << ") does not reach the work plane";
    throw NumericalError(msg.str());
  }
  const Eigen::Vector3d d = direction / norm;
  const double cos_theta = std::abs(d.z());
  SpotFootprint fp;
  if (config.defocus_mode == "fixed")
    fp.defocus_m = config.defocus_m;
  else if (config.defocus_mode == "field")
    fp.defocus_m = config.defocus_m + config.focus_distance_m * (1.0 / cos_theta - 1.0);
  const double w0 = 0.5 * config.spot_diameter_m;
  const double zr = config.rayleighLength();
  const double w = fp.defocus_m == 0.0 ? w0 : w0 * std::sqrt(1.0 + (fp.defocus_m / zr) * (fp.defocus_m / zr));
  const double a = 2.0 / (w * w);
  fp.radius_m = w;
  if (config.oblique_incidence)
  {
    fp.qxx = a * (1.0 - d.x() * d.x());
    fp.qxy = -a * d.x() * d.y();
    fp.qyy = a * (1.0 - d.y() * d.y());
    fp.major_radius_m = w / cos_theta;
  }
  else
  {
    fp.qxx = fp.qyy = a;
    fp.major_radius_m = w;
  }
  return fp;
}
}  // namespace scanhead
