/// \file energy_exports.cpp
#include "scanhead/report/energy_exports.hpp"
#include "scanhead/common/text_file.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <memory>

#include "scanhead/common/number_text.hpp"
#include "scanhead/report/colour_map.hpp"
#include "scanhead/report/png_writer.hpp"
#include "scanhead/report/task_pool.hpp"
#include "scanhead/report/tiff_writer.hpp"

namespace scanhead
{
namespace fs = std::filesystem;

namespace
{
constexpr int kColourSide = 2000;  // px; larger crops are shown by block maxima

}  // namespace

double addFieldImageTasks(TaskPool& pool, const std::string& dir_text, const std::string& stem,
                          std::shared_ptr<const EnergyMap> map, const std::string& description, const FieldUnits& units)
{
  const fs::path dir(dir_text);
  const double scale = map->peak();
  // The 16-bit PNG first: its zlib pass is the longest of the three.
  pool.add([=] { writePng((dir / (stem + "_16bit.png")).string(), energyMapToGray16(*map, scale)); });
  pool.add([=] {
    EnergyImageLayout layout;
    writePng((dir / (stem + ".png")).string(), renderEnergyMap(*map, scale, kColourSide, &layout));
    writeTextFile(dir / (stem + ".yaml"),
                  "# " + description +
                      "\n"
                      "# values: " +
                      units.quantity +
                      "\n"
                      "# " +
                      stem + "_16bit.png: value = pixel / 65535 * " + units.scale_key +
                      ", row 0 = top (+y up)\n"
                      "# " +
                      stem + ".png: inferno colour map, colour bar on the right from 0 (bottom) to " + units.scale_key +
                      " (top)\n"
                      "# " +
                      stem +
                      ".tiff: float32 values, row 0 = top, GeoTIFF pixel scale and tie point in metres\n"
                      "width: " +
                      std::to_string(map->width()) + "\nheight: " + std::to_string(map->height()) + "\npixel_m: " +
                      fullPrecisionText(map->pixel()) + "\norigin_m: [" + fullPrecisionText(map->origin().x()) + ", " +
                      fullPrecisionText(map->origin().y()) + "]  # lower-left corner\n" + units.scale_key + ": " +
                      fullPrecisionText(scale) + "\ncolour_image_block: " + std::to_string(layout.block) +
                      "  # pixels per colour-image pixel (block maximum)\n");
  });
  pool.add([=] {
    // TIFF rows run top to bottom: the map's row 0 is its lowest y.
    std::vector<float> top_down(static_cast<std::size_t>(map->width()) * static_cast<std::size_t>(map->height()));
    for (int r = 0; r < map->height(); ++r)
      std::copy(map->data().begin() + static_cast<std::ptrdiff_t>(r) * map->width(),
                map->data().begin() + static_cast<std::ptrdiff_t>(r + 1) * map->width(),
                top_down.begin() + static_cast<std::ptrdiff_t>(map->height() - 1 - r) * map->width());
    TiffScale tiff;
    tiff.pixel_x_m = tiff.pixel_y_m = map->pixel();
    tiff.x_left_m = map->origin().x();
    tiff.y_top_m = map->origin().y() + map->pixel() * map->height();
    tiff.description = units.quantity + ", " + description + ", pixel " + fullPrecisionText(map->pixel()) + " m";
    writeFloatTiff((dir / (stem + ".tiff")).string(), map->width(), map->height(), top_down.data(), tiff);
  });
  return scale;
}

double writeFieldImages(const std::string& dir, const std::string& stem, const EnergyMap& map,
                        const std::string& description, const FieldUnits& units)
{
  TaskPool pool(1);
  // The caller keeps the map: an aliasing pointer that owns nothing.
  const double scale = addFieldImageTasks(
      pool, dir, stem, std::shared_ptr<const EnergyMap>(std::shared_ptr<void>(), &map), description, units);
  pool.run();
  return scale;
}

std::vector<MapRegion> exportCrops(const Job& job, const EnergyConfig& config)
{
  std::vector<MapRegion> crops = jobParts(job, 2.0 * config.spot_diameter_m);
  if (crops.size() > config.crop_parts)
    crops.resize(config.crop_parts);
  for (const MapRegion& region : parseMapRegions(config.crop_regions))
    crops.push_back(region);
  return crops;
}

namespace
{
std::string overviewDescription(const TiledEnergyMap& map, int factor)
{
  return factor == 1 ? "the whole map at full resolution"
                     : "overview: means of " + std::to_string(factor) + " x " + std::to_string(factor) +
                           " pixels of the " + fullPrecisionText(map.pixel()) + " m map (full-resolution peak " +
                           fullPrecisionText(map.peak()) + " J/m^2)";
}

TiledEnergyMap::RegionRequest cropRequest(const TiledEnergyMap& map, const MapRegion& crop)
{
  const double p = map.pixel();
  const auto col0 = static_cast<std::int64_t>(std::floor((crop.min_corner.x() - map.origin().x()) / p));
  const auto row0 = static_cast<std::int64_t>(std::floor((crop.min_corner.y() - map.origin().y()) / p));
  const auto col1 = static_cast<std::int64_t>(std::ceil((crop.max_corner.x() - map.origin().x()) / p));
  const auto row1 = static_cast<std::int64_t>(std::ceil((crop.max_corner.y() - map.origin().y()) / p));
  return {col0, row0, col1 - col0, row1 - row0, TiledEnergyMap::blockFactor(col1 - col0, row1 - row0, kCropSide)};
}

EnergyMapViews::View cropView(const MapRegion& crop, int factor, EnergyMap grid)
{
  return {crop.name, std::make_shared<const EnergyMap>(std::move(grid)),
          factor == 1 ? crop.name + " at full resolution"
                      : crop.name + ": means of " + std::to_string(factor) + " x " + std::to_string(factor) +
                            " pixels (over " + std::to_string(kCropSide) + " pixels a side at full resolution)"};
}
}  // namespace

EnergyMapViews readEnergyMapViews(const TiledEnergyMap& map, const std::vector<MapRegion>& crops,
                                  const TiledEnergyMap::TileVisitor& visit)
{
  const int factor = map.overviewFactor(kOverviewSide);
  std::vector<TiledEnergyMap::RegionRequest> requests{{0, 0, map.width(), map.height(), factor}};
  for (const MapRegion& crop : crops)
    requests.push_back(cropRequest(map, crop));
  std::vector<EnergyMap> grids = map.regions(requests, visit);
  EnergyMapViews views;
  views.overview = {"energy_map", std::make_shared<const EnergyMap>(std::move(grids[0])),
                    overviewDescription(map, factor)};
  for (std::size_t k = 0; k < crops.size(); ++k)
    views.crops.push_back(cropView(crops[k], requests[k + 1].factor, std::move(grids[k + 1])));
  return views;
}

EnergyMapViews::View readCropView(const TiledEnergyMap& map, const MapRegion& crop)
{
  const TiledEnergyMap::RegionRequest request = cropRequest(map, crop);
  return cropView(crop, request.factor, std::move(map.regions({request}).front()));
}

void addEnergyViewTasks(TaskPool& pool, const std::string& dir_text, const EnergyMapViews& views)
{
  const fs::path dir(dir_text);
  addFieldImageTasks(pool, dir.string(), views.overview.stem, views.overview.grid, views.overview.description);
  if (!views.crops.empty())
    fs::create_directory(dir / "crops");
  for (const EnergyMapViews::View& crop : views.crops)
    addFieldImageTasks(pool, (dir / "crops").string(), crop.stem, crop.grid, crop.description);
}

void addEnergyExportTasks(TaskPool& pool, const std::string& dir_text, const TiledEnergyMap& map, const Job& job,
                          const EnergyConfig& config)
{
  // The tiled map's reads are not thread-safe (its tile cache may load spilled tiles): one task reads every grid of
  // it, then adds each grid's image tasks.
  pool.add([&pool, dir_text, &map, crops = exportCrops(job, config)] {
    addEnergyViewTasks(pool, dir_text, readEnergyMapViews(map, crops));
  });
}

void writeEnergyExports(const std::string& dir, const TiledEnergyMap& map, const Job& job, const EnergyConfig& config)
{
  TaskPool pool(1);
  addEnergyExportTasks(pool, dir, map, job, config);
  pool.run();
}
}  // namespace scanhead
