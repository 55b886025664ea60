/// \file optics_config.cpp
#include "scanhead/core/optics_config.hpp"

#include <cmath>
#include <sstream>

#include "scanhead/core/errors.hpp"

namespace scanhead
{
namespace
{
/// \brief Throws "<field> must be <relation> (got <value>)" unless \p ok and \p value is finite.
void require(bool ok, const std::string& field, const std::string& relation, double value)
{
  if (!ok || !std::isfinite(value))
  {
    std::ostringstream msg;
    msg << field << " must be " << relation << " (got " << value << ")";
    throw ConfigError(msg.str());
  }
}
}  // namespace

void OpticsConfig::validate() const
{
  if (urdf_path.empty())
  {
    throw ConfigError("optics.urdf_path must not be empty");
  }
  require(window_thickness_m >= 0.0, "optics.window_thickness_m", ">= 0", window_thickness_m);
  require(n_gas >= 1.0, "optics.n_gas", ">= 1", n_gas);
  require(n_window >= 1.0, "optics.n_window", ">= 1", n_window);
  require(field_half_width_m > 0.0, "optics.field_half_width_m", "> 0", field_half_width_m);
  require(newton_tolerance_m > 0.0, "optics.newton_tolerance_m", "> 0", newton_tolerance_m);
  require(newton_max_iterations >= 1, "optics.newton_max_iterations", ">= 1", newton_max_iterations);
}
}  // namespace scanhead
