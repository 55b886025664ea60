/// \file nominal_closed_form.cpp
/// \brief Closed-form direct model of the nominal head. The layout, the derivation (steps 1–4
/// below) and the comparison with OPT's transcribed eqs. 2–6 are documented on closedFormSpot in
/// nominal_closed_form.hpp.
#include "scanhead/optics/nominal_closed_form.hpp"

#include <cmath>

namespace scanhead
{
namespace
{
/// Signed distance [m] from a galvo axis (the z axis of the rotor frame) to the mirror surface
/// through \p mirror's origin with normal \p mirror's +x: e_m = n·p.
double surfaceOffset(const Eigen::Isometry3d& mirror)
{
  return mirror.linear().col(0).dot(mirror.translation());
}
}  // namespace

Eigen::Vector2d closedFormSpot(const OpticalGeometry& nominal, const OpticsConfig& config, const Eigen::Vector2d& q)
{
  constexpr double kQuarterPi = 0.78539816339744830962;
  const Eigen::Vector3d s = nominal.source.translation();
  const Eigen::Vector3d ax = nominal.mount_x.translation();
  const Eigen::Vector3d ay = nominal.mount_y.translation();
  const Eigen::Vector3d plane = nominal.work_plane.translation();
  const double em_x = surfaceOffset(nominal.mirror_x);
  const double em_y = surfaceOffset(nominal.mirror_y);
  const double ev = config.window_thickness_m;
  const double index_ratio = config.n_window / config.n_gas;  // n2 / n1

  const double beta = q.x() + kQuarterPi;
  const double gamma = q.y() + kQuarterPi;
  const double c2x = std::cos(2.0 * q.x());
  const double s2x = std::sin(2.0 * q.x());
  const double c2y = std::cos(2.0 * q.y());
  const double s2y = std::sin(2.0 * q.y());

  // 1. mirror X hit point (x only: y and z are the source's)
  const double u = ax.y() - s.y();
  const double x1 = ax.x() - (em_x + u * std::sin(beta)) / std::cos(beta);
  // 2. y travel from mirror X to mirror Y
  const double vy = ay.y() - s.y();
  const double vz = ay.z() - s.z();
  const double k1 = (vy * std::cos(gamma) + vz * std::sin(gamma) - em_y) / std::cos(gamma);
  // 3. windows
  const double k3 = std::sqrt(c2x * c2x * c2y * c2y - 1.0 + index_ratio * index_ratio);
  // 4. descent to the plane
  const double k2 = (s.z() - plane.z()) - 2.0 * ev;
  const double t2x = s2x / c2x;
  const double x = x1 + k1 * t2x + k2 * t2x / c2y + 2.0 * ev * s2x / k3 - plane.x();
  const double y = s.y() + k1 + k2 * s2y / c2y + 2.0 * ev * c2x * s2y / k3 - plane.y();
  return Eigen::Vector2d(x, y);
}
}  // namespace scanhead
