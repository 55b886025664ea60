/// \file energy_exports.cpp
#include "scanhead/core/energy_exports.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "scanhead/core/colour_map.hpp"
#include "scanhead/core/errors.hpp"
#include "scanhead/core/number_text.hpp"
#include "scanhead/core/png_writer.hpp"
#include "scanhead/core/tiff_writer.hpp"

namespace scanhead
{
namespace fs = std::filesystem;

namespace
{
constexpr int kColourSide = 2000;  // px; larger crops are shown by block maxima

bool closedContour(const Polyline& line)
{
  return line.type == PolylineType::Mark && line.role == PolylineRole::Contour && line.points.size() >= 4 &&
         (line.points.front() - line.points.back()).norm() <= 1e-9;
}

bool contains(const MapRegion& outer, const MapRegion& inner)
{
  return (outer.min_corner.array() <= inner.min_corner.array()).all() &&
         (outer.max_corner.array() >= inner.max_corner.array()).all();
}

void writeText(const fs::path& path, const std::string& text)
{
  std::ofstream out(path, std::ios::binary);
  out << text;
  if (!out.good())
    throw InputError(path.string() + ": cannot write");
}

std::string partName(std::size_t k)
{
  char name[32];
  std::snprintf(name, sizeof name, "part_%03zu", k);
  return name;
}
}  // namespace

std::vector<MapRegion> jobParts(const Job& job, double margin_m)
{
  std::vector<MapRegion> boxes;
  for (const Polyline& line : job.polylines)
  {
    if (!closedContour(line))
      continue;
    MapRegion box;
    box.min_corner = box.max_corner = line.points.front();
    for (const Eigen::Vector2d& p : line.points)
    {
      box.min_corner = box.min_corner.cwiseMin(p);
      box.max_corner = box.max_corner.cwiseMax(p);
    }
    boxes.push_back(box);
  }
  std::vector<MapRegion> parts;
  for (std::size_t i = 0; i < boxes.size(); ++i)
  {
    bool inner = false;
    for (std::size_t j = 0; j < boxes.size() && !inner; ++j)
      inner = j != i && contains(boxes[j], boxes[i]) && !(contains(boxes[i], boxes[j]) && j > i);
    if (inner)
      continue;
    MapRegion part = boxes[i];
    part.min_corner.array() -= margin_m;
    part.max_corner.array() += margin_m;
    part.name = partName(parts.size());
    parts.push_back(part);
  }
  return parts;
}

std::vector<MapRegion> parseMapRegions(const std::string& text)
{
  std::vector<MapRegion> regions;
  std::stringstream entries(text);
  std::string entry;
  while (std::getline(entries, entry, ';'))
  {
    if (entry.find_first_not_of(" \t") == std::string::npos)
      continue;
    std::stringstream fields(entry);
    std::string field;
    std::vector<std::string> parts;
    while (std::getline(fields, field, ','))
      parts.push_back(field);
    double v[4] = {};
    bool ok = parts.size() == 4 || parts.size() == 5;
    for (int k = 0; ok && k < 4; ++k)
      ok = parseNumber(parts[static_cast<std::size_t>(k)], v[k]) == NumberText::Ok;
    if (!ok || !(v[2] > v[0] && v[3] > v[1]))
      throw ConfigError("energy.crop_regions: '" + entry +
                        "' is not x0,y0,x1,y1[,name] in metres with x1 > x0 and y1 > y0");
    MapRegion region;
    region.min_corner = Eigen::Vector2d(v[0], v[1]);
    region.max_corner = Eigen::Vector2d(v[2], v[3]);
    region.name = parts.size() == 5 ? parts[4] : "region_" + std::to_string(regions.size());
    if (region.name.find_first_of("/\\ ") != std::string::npos || region.name.empty())
      throw ConfigError("energy.crop_regions: region name '" + region.name + "' must be a plain file name");
    regions.push_back(region);
  }
  return regions;
}

double writeEnergyImages(const std::string& dir_text, const std::string& stem, const EnergyMap& map,
                         const std::string& description, const std::string& quantity)
{
  const fs::path dir(dir_text);
  const double scale = map.peak();
  EnergyImageLayout layout;
  writePng((dir / (stem + ".png")).string(), renderEnergyMap(map, scale, kColourSide, &layout));
  writePng((dir / (stem + "_16bit.png")).string(), energyMapToGray16(map, scale));
  // TIFF rows run top to bottom: the map's row 0 is its lowest y.
  std::vector<float> top_down(static_cast<std::size_t>(map.width()) * static_cast<std::size_t>(map.height()));
  for (int r = 0; r < map.height(); ++r)
    std::copy(map.data().begin() + static_cast<std::ptrdiff_t>(r) * map.width(),
              map.data().begin() + static_cast<std::ptrdiff_t>(r + 1) * map.width(),
              top_down.begin() + static_cast<std::ptrdiff_t>(map.height() - 1 - r) * map.width());
  TiffScale tiff;
  tiff.pixel_x_m = tiff.pixel_y_m = map.pixel();
  tiff.x_left_m = map.origin().x();
  tiff.y_top_m = map.origin().y() + map.pixel() * map.height();
  tiff.description = quantity + ", " + description + ", pixel " + fullPrecisionText(map.pixel()) + " m";
  writeFloatTiff((dir / (stem + ".tiff")).string(), map.width(), map.height(), top_down.data(), tiff);
  writeText(dir / (stem + ".yaml"),
            "# " + description + "\n"
            "# values: " + quantity + "\n"
            "# " + stem + "_16bit.png: E = value / 65535 * scale_max_jpm2, row 0 = top (+y up)\n"
            "# " + stem + ".png: inferno colour map, colour bar on the right from 0 (bottom) to scale_max_jpm2 (top)\n"
            "# " + stem + ".tiff: float32 values, row 0 = top, GeoTIFF pixel scale and tie point in metres\n"
            "width: " + std::to_string(map.width()) + "\nheight: " + std::to_string(map.height()) +
            "\npixel_m: " + fullPrecisionText(map.pixel()) + "\norigin_m: [" + fullPrecisionText(map.origin().x()) +
            ", " + fullPrecisionText(map.origin().y()) + "]  # lower-left corner\nscale_max_jpm2: " +
            fullPrecisionText(scale) + "\ncolour_image_block: " + std::to_string(layout.block) +
            "  # pixels per colour-image pixel (block maximum)\n");
  return scale;
}

void writeEnergyExports(const std::string& dir_text, const TiledEnergyMap& map, const Job& job, const EnergyConfig& config)
{
  const fs::path dir(dir_text);
  const int factor = map.overviewFactor(kOverviewSide);
  const EnergyMap overview = factor == 1 ? map.toDense() : map.overview(factor);
  writeEnergyImages(dir.string(), "energy_map", overview,
                    factor == 1 ? "the whole map at full resolution"
                                : "overview: means of " + std::to_string(factor) + " x " + std::to_string(factor) +
                                      " pixels of the " + fullPrecisionText(map.pixel()) + " m map (full-resolution peak " +
                                      fullPrecisionText(map.peak()) + " J/m^2)");
  std::vector<MapRegion> crops = jobParts(job, 2.0 * config.spot_diameter_m);
  if (crops.size() > config.crop_parts)
    crops.resize(config.crop_parts);
  for (const MapRegion& region : parseMapRegions(config.crop_regions))
    crops.push_back(region);
  if (crops.empty())
    return;
  fs::create_directory(dir / "crops");
  for (const MapRegion& crop : crops)
  {
    const double p = map.pixel();
    const auto col0 = static_cast<std::int64_t>(std::floor((crop.min_corner.x() - map.origin().x()) / p));
    const auto row0 = static_cast<std::int64_t>(std::floor((crop.min_corner.y() - map.origin().y()) / p));
    const auto col1 = static_cast<std::int64_t>(std::ceil((crop.max_corner.x() - map.origin().x()) / p));
    const auto row1 = static_cast<std::int64_t>(std::ceil((crop.max_corner.y() - map.origin().y()) / p));
    if (col1 <= 0 || row1 <= 0 || col0 >= map.width() || row0 >= map.height())
      throw ConfigError("energy.crop_regions: region " + crop.name + " lies outside the energy map");
    writeEnergyImages((dir / "crops").string(), crop.name, map.region(col0, row0, col1 - col0, row1 - row0),
                      crop.name + " at full resolution");
  }
}
}  // namespace scanhead
