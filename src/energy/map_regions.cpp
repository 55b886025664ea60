/// \file map_regions.cpp
#include "scanhead/energy/map_regions.hpp"

#include <cstdio>
#include <sstream>

#include "scanhead/common/errors.hpp"
#include "scanhead/common/number_text.hpp"

namespace scanhead
{
namespace
{
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

void requireRegionsOnMap(const std::vector<MapRegion>& regions, const Eigen::Vector2d& min_corner,
                         const Eigen::Vector2d& max_corner)
{
  for (const MapRegion& r : regions)
    if ((r.max_corner.array() <= min_corner.array()).any() || (r.min_corner.array() >= max_corner.array()).any())
      throw ConfigError("energy.crop_regions: region " + r.name + " lies outside the energy map (x " +
                        fullPrecisionText(min_corner.x()) + " to " + fullPrecisionText(max_corner.x()) + " m, y " +
                        fullPrecisionText(min_corner.y()) + " to " + fullPrecisionText(max_corner.y()) + " m)");
}
}  // namespace scanhead
