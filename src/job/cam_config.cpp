#include "scanhead/job/cam_config.hpp"

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
}
}  // namespace scanhead
