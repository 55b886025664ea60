/// \file hinf_config.cpp
#include "scanhead/servo/hinf/hinf_config.hpp"

#include <cmath>

#include "scanhead/common/config_check.hpp"

namespace scanhead
{
using Eigen::MatrixXd;

StateSpace FirstOrderWeight::stateSpace() const
{
  const double a = ginf * std::sqrt(std::abs(g0 * g0 - 1.0));
  const double b = g0 * w0_rad_s * std::sqrt(std::abs(ginf * ginf - 1.0));
  const double c = std::sqrt(std::abs(g0 * g0 - 1.0));
  const double d = w0_rad_s * std::sqrt(std::abs(ginf * ginf - 1.0));
  // (cs + d)/(as + b) = c/a + (d − bc/a)/(as + b).
  StateSpace w;
  w.a = MatrixXd::Constant(1, 1, -b / a);
  w.b = MatrixXd::Constant(1, 1, 1.0);
  w.c = MatrixXd::Constant(1, 1, (d - b * c / a) / a);
  w.d = MatrixXd::Constant(1, 1, c / a);
  return w;
}

void FirstOrderWeight::validate(const std::string& prefix) const
{
  requireSetting(g0 > 0.0 && g0 != 1.0, prefix + ".g0", "> 0 and != 1", g0);
  requireSetting(ginf > 0.0 && ginf != 1.0, prefix + ".ginf", "> 0 and != 1", ginf);
  requireSetting(w0_rad_s > 0.0, prefix + ".w0_rad_s", "> 0", w0_rad_s);
}

void HinfConfig::validate() const
{
  w1.validate("servo.hinf.w1");
  w2.validate("servo.hinf.w2");
  w3.validate("servo.hinf.w3");
  requireSetting(gamma_tolerance >= 1e-6 && gamma_tolerance <= 0.5, "servo.hinf.gamma_tolerance", "in [1e-6, 0.5]",
                 gamma_tolerance);
  requireSetting(reduced_order >= 1 && reduced_order <= 9, "servo.hinf.reduced_order", "in [1, 9]", reduced_order);
}
}  // namespace scanhead
