/// \file file_survey.cpp
/// \brief The survey of a whole layered file (file_survey.hpp).
#include "scanhead/job/file_survey.hpp"

#include "scanhead/job/scan_job.hpp"

namespace scanhead
{
void FileSurvey::begin(double rotation_deg)
{
  *this = FileSurvey();
  surveyed = true;
  box_rotation_deg = rotation_deg;
  rotation_ = placementRotation(rotation_deg);
}

void FileSurvey::addPoint(const Eigen::Vector2d& point)
{
  // The same product as rotatedBoundingBox(), so the box is bit for bit the whole-file one.
  const Eigen::Vector2d q = rotation_ * point;
  box_lo = has_points ? box_lo.cwiseMin(q) : q;
  box_hi = has_points ? box_hi.cwiseMax(q) : q;
  has_points = true;
}

void FileSurvey::addTime(std::size_t layer, double seconds)
{
  if (layer_path_s.size() <= layer)
    layer_path_s.resize(layer + 1, 0.0);
  layer_path_s[layer] += seconds;
}

void FileSurvey::add(std::size_t layer, const Polyline& polyline)
{
  double length_m = 0.0;
  for (std::size_t i = 0; i < polyline.points.size(); ++i)
  {
    addPoint(polyline.points[i]);
    if (i > 0)
      length_m += (polyline.points[i] - polyline.points[i - 1]).norm();
  }
  addTime(layer, polyline.dwell_s + (length_m > 0.0 ? length_m / polyline.speed_mps : 0.0));
}

void FileSurvey::finish(std::size_t file_layers)
{
  layers = file_layers;
  layer_path_s.resize(file_layers, 0.0);
}
}  // namespace scanhead
