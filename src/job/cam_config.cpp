#include "scanhead/job/cam_config.hpp"

#include <cmath>

#include "scanhead/common/config_check.hpp"
#include "scanhead/common/errors.hpp"
#include "scanhead/job/recipe.hpp"

namespace scanhead
{
void CamConfig::validate() const
{
  requireSetting(layer >= -1, "cam.layer", ">= -1 (-1: all layers)", layer);
  if (units != "m" && units != "mm")
    throw ConfigError("cam.units must be m or mm (got '" + units + "')");
  requireSetting(mark_speed_mps > 0.0, "cam.mark_speed_mps", "> 0", mark_speed_mps);
  requireSetting(jump_speed_mps > 0.0, "cam.jump_speed_mps", "> 0", jump_speed_mps);
  requireSetting(mark_power_w >= 0.0, "cam.mark_power_w", ">= 0", mark_power_w);
  requireSetting(mark_power_w <= kMaxLaserPower_w, "cam.mark_power_w",
                 "<= 1e+06 W (no continuous-wave laser reaches it; LPBF: 200 W - 1 kW)", mark_power_w);
  if (segment_power != "auto" && segment_power != "coefficient" && segment_power != "watts")
    throw ConfigError("cam.segment_power must be auto, coefficient or watts (got '" + segment_power + "')");
  // A plate is at most a few hundred mm: 1 km is a unit mistake, not a placement.
  for (int axis = 0; axis < 2; ++axis)
    requireSetting(std::isfinite(offset_m[axis]) && std::abs(offset_m[axis]) <= 1e3,
                   axis == 0 ? "cam.offset_m[0]" : "cam.offset_m[1]", "a finite offset within 1 km, in m",
                   offset_m[axis]);
  requireSetting(std::isfinite(rotation_deg) && std::abs(rotation_deg) <= 360.0, "cam.rotation_deg",
                 "within [-360, 360] degrees", rotation_deg);
}
}  // namespace scanhead
