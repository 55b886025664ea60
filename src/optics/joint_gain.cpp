/// \file joint_gain.cpp
/// \brief Largest joint rate per unit spot speed over the field.
#include "scanhead/optics/joint_gain.hpp"

#include <Eigen/LU>
#include <algorithm>

namespace scanhead
{
Eigen::Vector2d jointRateGains(const OpticalModel& optics, double half_width_m, int probes)
{
  Eigen::Vector2d gains = Eigen::Vector2d::Zero();
  Eigen::Vector2d q = Eigen::Vector2d::Zero();
  const int n = std::max(probes, 2);
  for (int j = 0; j < n; ++j)
  {
    for (int i = 0; i < n; ++i)
    {
      const Eigen::Vector2d x(-half_width_m + 2.0 * half_width_m * i / (n - 1),
                              -half_width_m + 2.0 * half_width_m * j / (n - 1));
      q = optics.inverse(x, q);
      const Eigen::Matrix2d inverse_jacobian = optics.jacobian(q).inverse();
      gains.x() = std::max(gains.x(), inverse_jacobian.row(0).norm());
      gains.y() = std::max(gains.y(), inverse_jacobian.row(1).norm());
    }
  }
  return gains;
}
}  // namespace scanhead
