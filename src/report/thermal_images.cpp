/// \file thermal_images.cpp
#include "scanhead/report/thermal_images.hpp"

#include "scanhead/report/energy_exports.hpp"

namespace scanhead
{
namespace
{
/// A cell grid at integer cell origins (i0, j0) as a float map (row 0 = lowest y).
template <class T>
EnergyMap cellMap(double cell_m, std::int64_t i0, std::int64_t j0, int width, int height, const std::vector<T>& values)
{
  const Eigen::Vector2d lo(static_cast<double>(i0) * cell_m, static_cast<double>(j0) * cell_m);
  EnergyMap map(lo, lo + cell_m * Eigen::Vector2d(width, height), cell_m);
  for (int r = 0; r < height; ++r)
    for (int c = 0; c < width; ++c)
      map.row(r)[c] = static_cast<float>(values[static_cast<std::size_t>(r) * static_cast<std::size_t>(width) + c]);
  return map;
}
}  // namespace

void writeThermalImages(const std::string& dir, const ThermalLayer& thermal)
{
  const ThermalWindow window = thermal.window();
  if (window.width > 0 && window.height > 0)
    writeFieldImages(
        dir, "thermal_temperature",
        cellMap(window.cell_m, window.origin_i, window.origin_j, window.width, window.height, window.rise_k),
        "the thermal window at the end of its time window",
        FieldUnits{"temperature rise over the bed [K]", "scale_max_k"});
  const MeltedRaster melted = thermal.meltedRaster();
  if (melted.count > 0 && melted.width > 0 && melted.height > 0)
    writeFieldImages(
        dir, "thermal_melted",
        cellMap(melted.cell_m, melted.origin_i, melted.origin_j, melted.width, melted.height, melted.melted),
        "cells melted at least once", FieldUnits{"melted (1) or powder (0)", "scale_max"});
}
}  // namespace scanhead
