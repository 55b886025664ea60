/// \file servo_config.cpp
#include "scanhead/servo/servo_config.hpp"

#include <sstream>

#include "scanhead/common/config_check.hpp"
#include "scanhead/common/errors.hpp"

namespace scanhead
{
void AxisLoopConfig::validate(const std::string& axis) const
{
  const std::string prefix = "servo." + axis + ".";
  requireSetting(bandwidth_hz > 0.0, prefix + "bandwidth_hz", "> 0", bandwidth_hz);
  requireSetting(damping > 0.0, prefix + "damping", "> 0", damping);
  requireSetting(pole_ratio > 0.0, prefix + "pole_ratio", "> 0", pole_ratio);
  plant.validate(prefix + "plant");
  gains.validate(prefix + "gains");
}

void ServoConfig::validate() const
{
  if (model != "closed_loop_3rd_order" && model != "cascade")
  {
    throw ConfigError("servo.model: unknown '" + model + "' (known: cascade, closed_loop_3rd_order)");
  }
  x.validate("x");
  y.validate("y");
  requireSetting(kc_over_jeq > 0.0, "servo.kc_over_jeq", "> 0", kc_over_jeq);
  requireSetting(controller_rate_hz > 0.0, "servo.controller_rate_hz", "> 0", controller_rate_hz);
  // Digital galvo servo loops run at 10–200 kHz (THESIS bench 20 kHz, this NC 100 kHz); each
  // controller period is a step of the cascade model, so the rate sets its work per machine second.
  requireSetting(controller_rate_hz >= kMinControllerRate_hz && controller_rate_hz <= kMaxControllerRate_hz,
                 "servo.controller_rate_hz", "in [1000, 1e+06] Hz (the range of digital galvo servo loops)",
                 controller_rate_hz);
  if (feedforward_derivatives != "nc" && feedforward_derivatives != "differentiate")
  {
    throw ConfigError("servo.feedforward_derivatives: unknown '" + feedforward_derivatives +
                      "' (known: nc, differentiate)");
  }
  if (position_controller != "pd" && position_controller != "hinf")
  {
    throw ConfigError("servo.position_controller: unknown '" + position_controller + "' (known: pd, hinf)");
  }
  if (position_controller == "hinf" && model != "cascade")
  {
    throw ConfigError("servo.position_controller: hinf needs servo.model: cascade (got '" + model + "')");
  }
  hinf.validate();
}
}  // namespace scanhead
