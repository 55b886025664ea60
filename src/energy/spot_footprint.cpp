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
  return SpotFootprintModel(config)(direction);
}

SpotFootprintModel::SpotFootprintModel(const EnergyConfig& config)
  : defocus_mode_(config.defocus_mode == "fixed"   ? Defocus::kFixed
                  : config.defocus_mode == "field" ? Defocus::kField
                                                   : Defocus::kNone)
  , defocus_m_(config.defocus_m)
  , focus_distance_m_(config.focus_distance_m)
  , w0_(0.5 * config.spot_diameter_m)
  , rayleigh_m_(config.rayleighLength())
  , oblique_incidence_(config.oblique_incidence)
{
}

SpotFootprint SpotFootprintModel::operator()(const Eigen::Vector3d& direction) const
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
  if (defocus_mode_ == Defocus::kFixed)
    fp.defocus_m = defocus_m_;
  else if (defocus_mode_ == Defocus::kField)
    fp.defocus_m = defocus_m_ + focus_distance_m_ * (1.0 / cos_theta - 1.0);
  const double w =
      fp.defocus_m == 0.0 ? w0_ : w0_ * std::sqrt(1.0 + (fp.defocus_m / rayleigh_m_) * (fp.defocus_m / rayleigh_m_));
  const double a = 2.0 / (w * w);
  fp.radius_m = w;
  if (oblique_incidence_)
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
