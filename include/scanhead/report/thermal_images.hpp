/// \file thermal_images.hpp
/// \brief Images of the thermal view: the temperature rise in the window at the end of its time
/// window, and the cells that melted.
#pragma once

#include <string>

#include "scanhead/thermal/thermal_layer.hpp"

namespace scanhead
{
/// \brief Writes thermal_temperature.* (rise over the bed [K] in the final window) and
/// thermal_melted.* (1 where a cell melted, over the melted cells' bounding box) into \p dir, in the
/// formats of writeFieldImages (colour PNG, 16-bit PNG, float TIFF, YAML with the geometry).
void writeThermalImages(const std::string& dir, const ThermalLayer& thermal);
}  // namespace scanhead
