/// \file energy_config.cpp
#include "scanhead/core/energy_config.hpp"

#include <cmath>
#include <sstream>
#include <string>

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

void EnergyConfig::validate() const
{
  require(spot_diameter_m > 0.0, "energy.spot_diameter_m", "> 0", spot_diameter_m);
  require(pixel_m > 0.0, "energy.pixel_m", "> 0", pixel_m);
  require(max_substep_radii > 0.0, "energy.max_substep_radii", "> 0", max_substep_radii);
  // Below one radius the truncated footprint misrepresents the spot (1-D tail mass beyond w: 4.6 %).
  require(truncation_radii >= 1.0, "energy.truncation_radii", ">= 1", truncation_radii);
  require(map_margin_m >= 0.0, "energy.map_margin_m", ">= 0", map_margin_m);
  require(corner_min_angle_deg >= 0.0 && corner_min_angle_deg < 180.0, "energy.corner_min_angle_deg",
          "in [0, 180)", corner_min_angle_deg);
}
}  // namespace scanhead
