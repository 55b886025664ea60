/// \file energy_config.cpp
#include "scanhead/energy/energy_config.hpp"

#include <cmath>
#include <sstream>
#include <string>

#include "scanhead/common/config_check.hpp"
#include "scanhead/common/errors.hpp"
#include "scanhead/common/number_text.hpp"
#include "scanhead/energy/map_regions.hpp"

namespace scanhead
{
void EnergyConfig::validate() const
{
  requireSetting(spot_diameter_m > 0.0, "energy.spot_diameter_m", "> 0", spot_diameter_m);
  requireSetting(pixel_m > 0.0, "energy.pixel_m", "> 0", pixel_m);
  // No lens focuses below the diffraction limit: w0 >= M²·λ/(π·NA) with NA <= 1.
  const double diffraction_limit_m = 2.0 * beam_quality_m2 * wavelength_m / M_PI;
  requireSetting(spot_diameter_m >= diffraction_limit_m, "energy.spot_diameter_m",
                 ">= 2·M²·λ/π = " + significantText(diffraction_limit_m, 3) +
                     " m (the diffraction limit at energy.wavelength_m and energy.beam_quality_m2, NA <= 1)",
                 spot_diameter_m);
  // The map must resolve the spot: a pixel wider than the 1/e² radius w cannot show the Gaussian
  // (it spans < 2 pixels a radius); below d/100 a finer map shows nothing new while the work of
  // a sample grows as (d/pixel)².
  requireSetting(pixel_m <= kMaxPixelPerDiameter * spot_diameter_m, "energy.pixel_m",
                 "<= energy.spot_diameter_m/2 = " + significantText(kMaxPixelPerDiameter * spot_diameter_m, 6) +
                     " m (a pixel wider than the spot radius cannot resolve the spot)",
                 pixel_m);
  requireSetting(pixel_m >= kMinPixelPerDiameter * spot_diameter_m, "energy.pixel_m",
                 ">= energy.spot_diameter_m/100 = " + significantText(kMinPixelPerDiameter * spot_diameter_m, 6) +
                     " m (finer resolves nothing more; the work a sample grows as (d/pixel)²)",
                 pixel_m);
  if (method != "trapezoid" && method != "exact" && method != "sampled")
    throw ConfigError("energy.method must be trapezoid, exact or sampled (got '" + method + "')");
  // Above 1 µm a merged stroke could misplace the deposit by 5 % of its peak (1.77·tol/w at w = 35 µm).
  requireSetting(stroke_tolerance_m >= 0.0 && stroke_tolerance_m <= 1.0e-6, "energy.stroke_tolerance_m",
                 "in [0, 1e-6] m", stroke_tolerance_m);
  requireSetting(max_substep_radii > 0.0, "energy.max_substep_radii", "> 0", max_substep_radii);
  // Sub-steps a sample: v·Ts/(k·w); below 0.01 the work grows 50× the default's for a ripple far
  // below float rounding (2·exp(-π²/(2·0.5²)) = 5e-9 already at 0.5).
  requireSetting(max_substep_radii >= 0.01, "energy.max_substep_radii",
                 ">= 0.01 (finer sub-steps only add work: the ripple is 5e-9 at 0.5)", max_substep_radii);
  // Below one radius the truncated footprint misrepresents the spot (1-D tail mass beyond w: 4.6 %).
  requireSetting(truncation_radii >= 1.0, "energy.truncation_radii", ">= 1", truncation_radii);
  // Beyond 5 radii the Gaussian is exp(-50) = 2e-22 of its peak, far below float rounding (6e-8,
  // reached at 2.9 radii), while the drawn area grows as the square of the radius.
  requireSetting(truncation_radii <= kMaxTruncationRadii, "energy.truncation_radii",
                 "<= 5 (exp(-2·5²) = 2e-22 of the peak: nothing left to draw, only work)", truncation_radii);
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
  // 30-bit point ids of the nearest-path index (contour_error.hpp).
  requireSetting(contour_max_samples <= (std::size_t(1) << 30), "energy.contour_max_samples", "<= 2^30 = 1073741824",
                 static_cast<double>(contour_max_samples));
  requireSetting(std::isfinite(contour_lag_s) && contour_lag_s < 1.0, "energy.contour_lag_s",
                 "finite and < 1 s (< 0: filter + servo delay)", contour_lag_s);
  requireSetting(same_instant_window_s >= 0.0 && same_instant_window_s <= 0.01, "energy.same_instant_window_s",
                 "in [0, 0.01] s", same_instant_window_s);
  parseMapRegions(crop_regions);  // a bad crop is reported before the run, not after it
}

double EnergyConfig::rayleighLength() const
{
  const double w0 = 0.5 * spot_diameter_m;
  return M_PI * w0 * w0 / (beam_quality_m2 * wavelength_m);
}
}  // namespace scanhead
