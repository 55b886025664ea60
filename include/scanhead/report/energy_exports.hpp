/// \file energy_exports.hpp
/// \brief Images of the sparse energy map: a downsampled overview of the whole map, full-resolution
/// crops of each part (each square of the THESIS job) and of user regions.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "scanhead/energy/energy_config.hpp"
#include "scanhead/energy/map_regions.hpp"
#include "scanhead/energy/tiled_energy_map.hpp"
#include "scanhead/job/scan_job.hpp"
#include "scanhead/report/task_pool.hpp"

namespace scanhead
{
/// \brief How the values of a field image are named in its files.
struct FieldUnits
{
  std::string quantity = "energy density [J/m^2]";  ///< what the floats are (TIFF description, YAML comment)
  std::string scale_key = "scale_max_jpm2";         ///< the YAML key of the colour and 16-bit scale
};

/// \brief Writes \p stem.png (inferno with colour bar), \p stem_16bit.png (linear 0..scale),
/// \p stem.tiff (float32, with the pixel size and position as GeoTIFF tags) and \p stem.yaml
/// (geometry and scale) for the grid \p map into \p dir (any field on a grid: the thermal view
/// writes temperatures this way). \return the scale used (the grid's peak)
double writeFieldImages(const std::string& dir, const std::string& stem, const EnergyMap& map,
                        const std::string& description, const FieldUnits& units = FieldUnits());

/// \brief writeFieldImages as three tasks of \p pool (16-bit PNG; colour PNG and YAML; TIFF), which
/// share \p map. \return the scale used (the grid's peak)
double addFieldImageTasks(TaskPool& pool, const std::string& dir, const std::string& stem,
                          std::shared_ptr<const EnergyMap> map, const std::string& description,
                          const FieldUnits& units = FieldUnits());

/// \brief The grids the energy exports draw, read from the tiled map: the overview (energy_map.*) and each crop
/// (crops/<name>.*), with the descriptions their files carry.
struct EnergyMapViews
{
  struct View
  {
    std::string stem;                       ///< file stem
    std::shared_ptr<const EnergyMap> grid;  ///< full resolution, or block means
    std::string description;
  };
  View overview;
  std::vector<View> crops;
};

/// \brief The regions writeEnergyExports crops: the first config.crop_parts parts of \p job, then every
/// config.crop_regions region. \throws ConfigError from parseMapRegions
std::vector<MapRegion> exportCrops(const Job& job, const EnergyConfig& config);

/// \brief Reads the overview and the \p crops from \p map in one pass over its tiles (TiledEnergyMap::regions), showing
/// \p visit each touched tile (the run's track energy and corner peaks are served by the same reads). Not thread-safe
/// (the map's reads share its spill file's block cache). A run reads them while its last pass runs on the other core
/// (EnergyStage::finish), not while writing.
EnergyMapViews readEnergyMapViews(const TiledEnergyMap& map, const std::vector<MapRegion>& crops,
                                  const TiledEnergyMap::TileVisitor& visit = {});
/// \brief One crop of \p map as readEnergyMapViews reads it (a crop chosen after the pass: the worst corner).
EnergyMapViews::View readCropView(const TiledEnergyMap& map, const MapRegion& crop);

/// \brief The image tasks of \p views (three a grid, addFieldImageTasks) into \p dir; the crops folder is created now.
void addEnergyViewTasks(TaskPool& pool, const std::string& dir, const EnergyMapViews& views);

/// \brief writeEnergyExports as tasks of \p pool: one reads the tiled map (readEnergyMapViews) and
/// adds the grids' image tasks (addEnergyViewTasks); \p map, \p pool must outlive pool.run().
/// \throws ConfigError from parseMapRegions
void addEnergyExportTasks(TaskPool& pool, const std::string& dir, const TiledEnergyMap& map, const Job& job,
                          const EnergyConfig& config);

/// \brief The whole export of a run into \p dir: the overview (full resolution up to
/// kOverviewSide pixels a side, else block means) as energy_map.*, the first config.crop_parts
/// parts and every config.crop_regions region under crops/ (full resolution up to kCropSide
/// pixels a side, else block means).
/// \throws ConfigError from parseMapRegions; InputError on I/O errors
void writeEnergyExports(const std::string& dir, const TiledEnergyMap& map, const Job& job, const EnergyConfig& config);

constexpr int kOverviewSide = 4000;  ///< px, the longer side of energy_map.* at most
constexpr int kCropSide = 8000;      ///< px, the longer side of a crop at most (256 MB of floats)
}  // namespace scanhead
