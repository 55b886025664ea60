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
  requireSetting(track_max_samples >= 1, "energy.track_max_samples", ">= 1", static_cast<double>(track_max_samples));
  requireSetting(tile_cache_bytes >= 1048576, "energy.tile_cache_bytes", ">= 1048576 (1 MiB)",
                 static_cast<double>(tile_cache_bytes));
  if (defocus_mode != "none" && defocus_mode != "fixed" && defocus_mode != "field")
    throw ConfigError("energy.defocus_mode must be none, fixed or field (got '" + defocus_mode + "')");
  requireSetting(std::isfinite(defocus_m), "energy.defocus_m", "finite", defocus_m);
  requireSetting(focus_distance_m > 0.0, "energy.focus_distance_m", "> 0", focus_distance_m);
  requireSetting(wavelength_m > 0.0, "energy.wavelength_m", "> 0", wavelength_m);
  requireSetting(beam_quality_m2 >= 1.0, "energy.beam_quality_m2", ">= 1", beam_quality_m2);
}

double EnergyConfig::rayleighLength() const
{
  const double w0 = 0.5 * spot_diameter_m;
  return M_PI * w0 * w0 / (beam_quality_m2 * wavelength_m);
}
}  // namespace scanhead
