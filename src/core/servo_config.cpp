/// \file servo_config.cpp
#include "scanhead/core/servo_config.hpp"

#include <sstream>

#include "scanhead/core/errors.hpp"

namespace scanhead
{
namespace
{
/// \brief Throws "<field> must be > 0 (got <value>)" unless value > 0 (NaN fails too).
void requirePositive(const std::string& field, double value)
{
  if (!(value > 0.0))
  {
    std::ostringstream msg;
    msg << field << " must be > 0 (got " << value << ")";
    throw ConfigError(msg.str());
  }
}
}  // namespace

void AxisLoopConfig::validate(const std::string& axis) const
{
  const std::string prefix = "servo." + axis + ".";
  requirePositive(prefix + "bandwidth_hz", bandwidth_hz);
  requirePositive(prefix + "damping", damping);
  requirePositive(prefix + "pole_ratio", pole_ratio);
}

void ServoConfig::validate() const
{
  if (model != "closed_loop_3rd_order")
  {
    throw ConfigError("servo.model: unknown '" + model + "' (known: closed_loop_3rd_order)");
  }
  x.validate("x");
  y.validate("y");
  requirePositive("servo.kc_over_jeq", kc_over_jeq);
}
}  // namespace scanhead
