/// \file optics_config.cpp
#include "scanhead/optics/optics_config.hpp"

#include <cmath>
#include <sstream>

#include "scanhead/common/config_check.hpp"
#include "scanhead/common/errors.hpp"

namespace scanhead
{
void OpticsConfig::validate() const
{
  if (urdf_path.empty())
  {
    throw ConfigError("optics.urdf_path must not be empty");
  }
  if (defects.empty())
  {
    throw ConfigError("optics.defects must not be empty (nominal, opt_table2, random:seed=N or a defect set file)");
  }
  requireSetting(window_thickness_m >= 0.0, "optics.window_thickness_m", ">= 0", window_thickness_m);
  requireSetting(n_gas >= 1.0, "optics.n_gas", ">= 1", n_gas);
  requireSetting(n_window >= 1.0, "optics.n_window", ">= 1", n_window);
  requireSetting(field_half_width_m > 0.0, "optics.field_half_width_m", "> 0", field_half_width_m);
  requireSetting(newton_tolerance_m > 0.0, "optics.newton_tolerance_m", "> 0", newton_tolerance_m);
  requireSetting(newton_max_iterations >= 1, "optics.newton_max_iterations", ">= 1", newton_max_iterations);
}
}  // namespace scanhead
