/// \file map_regions.hpp
/// \brief Named rectangles of the work plane: the parts of a job (its outer closed contours) and
/// the regions a user asks for (energy.crop_regions), for full-resolution crops of the energy map.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "scanhead/job/scan_job.hpp"

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

/// \brief Checks that every region meets the map [min_corner, max_corner].
/// \throws ConfigError naming energy.crop_regions and the region that lies outside
void requireRegionsOnMap(const std::vector<MapRegion>& regions, const Eigen::Vector2d& min_corner,
                         const Eigen::Vector2d& max_corner);
}  // namespace scanhead
