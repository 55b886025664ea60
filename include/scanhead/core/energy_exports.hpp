/// \file energy_exports.hpp
/// \brief Images of the sparse energy map: a downsampled overview of the whole map, full-resolution
/// crops of each part (each square of the THESIS job) and of user regions.
#pragma once

#include <string>
#include <vector>

#include "scanhead/core/energy_config.hpp"
#include "scanhead/core/scan_job.hpp"
#include "scanhead/core/tiled_energy_map.hpp"

namespace scanhead
{
/// \brief A named rectangle of the work plane [m].
struct MapRegion
{
  std::string name;
  Eigen::Vector2d min_corner = Eigen::Vector2d::Zero();
  Eigen::Vector2d max_corner = Eigen::Vector2d::Zero();
};

/// \brief The parts of a job: the bounding boxes of its closed contour marks (first point = last
/// point, role Contour) that no other such box contains, in job order, grown by \p margin_m;
/// named part_000, part_001… (on the THESIS job: one per square, bottom right first).
std::vector<MapRegion> jobParts(const Job& job, double margin_m);

/// \brief Regions from text "x0,y0,x1,y1[,name];…" [m] (energy.crop_regions); "" gives none.
/// \throws ConfigError naming energy.crop_regions and the bad entry
std::vector<MapRegion> parseMapRegions(const std::string& text);

/// \brief Writes \p stem.png (inferno with colour bar), \p stem_16bit.png (linear 0..scale),
/// \p stem.tiff (float32 J/m², with the pixel size and position as GeoTIFF tags) and \p stem.yaml
/// (geometry and scale) for \p map into \p dir; \p quantity names what the floats are (any field on a
/// grid: the thermal view writes temperatures this way). \return the scale used (the map's peak)
double writeEnergyImages(const std::string& dir, const std::string& stem, const EnergyMap& map,
                         const std::string& description, const std::string& quantity = "energy density [J/m^2]");

/// \brief The whole export of a run into \p dir: the overview (full resolution up to
/// kOverviewSide pixels a side, else block means) as energy_map.*, the first config.crop_parts
/// parts and every config.crop_regions region at full resolution under crops/.
/// \throws ConfigError from parseMapRegions; InputError on I/O errors
void writeEnergyExports(const std::string& dir, const TiledEnergyMap& map, const Job& job, const EnergyConfig& config);

constexpr int kOverviewSide = 4000;  ///< px, the longer side of energy_map.* at most
}  // namespace scanhead
