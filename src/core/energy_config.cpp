/// \file energy_config.cpp
#include "scanhead/core/energy_config.hpp"

#include <cmath>
#include <sstream>
#include <string>

#include "scanhead/core/config_check.hpp"
#include "scanhead/core/errors.hpp"

namespace scanhead
{
void EnergyConfig::validate() const
{
  requireSetting(spot_diameter_m > 0.0, "energy.spot_diameter_m", "> 0", spot_diameter_m);
  requireSetting(pixel_m > 0.0, "energy.pixel_m", "> 0", pixel_m);
  requireSetting(max_substep_radii > 0.0, "energy.max_substep_radii", "> 0", max_substep_radii);
  // Below one radius the truncated footprint misrepresents the spot (1-D tail mass beyond w: 4.6 %).
  requireSetting(truncation_radii >= 1.0, "energy.truncation_radii", ">= 1", truncation_radii);
  requireSetting(map_margin_m >= 0.0, "energy.map_margin_m", ">= 0", map_margin_m);
  requireSetting(corner_min_angle_deg >= 0.0 && corner_min_angle_deg < 180.0, "energy.corner_min_angle_deg",
          "in [0, 180)", corner_min_angle_deg);
  requireSetting(laser_path_tolerance_m > 0.0, "energy.laser_path_tolerance_m", "> 0", laser_path_tolerance_m);
  requireSetting(track_exclude_ends_m >= 0.0, "energy.track_exclude_ends_m", ">= 0", track_exclude_ends_m);
}
}  // namespace scanhead
