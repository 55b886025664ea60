/// \file servo_config.cpp
#include "scanhead/core/servo_config.hpp"

#include <sstream>

#include "scanhead/core/config_check.hpp"
#include "scanhead/core/errors.hpp"

namespace scanhead
{
void AxisLoopConfig::validate(const std::string& axis) const
{
  const std::string prefix = "servo." + axis + ".";
  requireSetting(bandwidth_hz > 0.0, prefix + "bandwidth_hz", "> 0", bandwidth_hz);
  requireSetting(damping > 0.0, prefix + "damping", "> 0", damping);
  requireSetting(pole_ratio > 0.0, prefix + "pole_ratio", "> 0", pole_ratio);
}

void ServoConfig::validate() const
{
  if (model != "closed_loop_3rd_order")
  {
    throw ConfigError("servo.model: unknown '" + model + "' (known: closed_loop_3rd_order)");
  }
  x.validate("x");
  y.validate("y");
  requireSetting(kc_over_jeq > 0.0, "servo.kc_over_jeq", "> 0", kc_over_jeq);
}
}  // namespace scanhead
