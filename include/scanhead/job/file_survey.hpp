/// \file file_survey.hpp
/// \brief What a reader saw of a whole layered file (every layer) while it kept only the layer asked for.
///
/// A build file holds hundreds to thousands of layers; a run, cam.centre and a study's time estimate each
/// need one layer's polylines plus a few numbers about all of them. The CLI and segment readers fill this
/// survey in the same pass as the layer they keep, so nothing needs every layer in memory at once:
///  * layers: how many the file has (a study makes one case per layer);
///  * the bounding box of every polyline point of every layer, in the frame rotated by box_rotation_deg
///    (cam.rotation_deg), the same points and the same arithmetic as rotatedBoundingBox() of the whole
///    file read at once (cam.centre places every layer of a build with it, bit for bit as before);
///  * per layer, the path time Σ (length / programmed speed) + dwells of its polylines: the time the NC
///    would need without acceleration limits, what a study's estimate scales one planned layer by.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <vector>

namespace scanhead
{
struct Polyline;

struct FileSurvey
{
  std::size_t layers = 1;         ///< layers of the file (CLI, segment files; other jobs: 1)
  bool surveyed = false;          ///< filled by a layered-file reader (false: the job is the whole file)
  double box_rotation_deg = 0.0;  ///< the frame of box_lo/box_hi: points rotated by this [deg]
  bool has_points = false;        ///< box_lo/box_hi hold a box (the file has at least one polyline point)
  Eigen::Vector2d box_lo = Eigen::Vector2d::Zero(), box_hi = Eigen::Vector2d::Zero();  ///< [m]
  std::vector<double> layer_path_s;  ///< per layer, Σ length / speed + dwell of its polylines [s]

  /// \brief Starts the survey of a file whose box is measured after a rotation by \p rotation_deg.
  void begin(double rotation_deg);
  /// \brief Adds \p polyline (any layer) to layer \p layer: its points to the box, its time to the layer's.
  void add(std::size_t layer, const Polyline& polyline);
  /// \brief Adds one point [m] to the box.
  void addPoint(const Eigen::Vector2d& point);
  /// \brief Adds \p seconds of path time to layer \p layer.
  void addTime(std::size_t layer, double seconds);
  /// \brief Ends the survey: \p file_layers layers (the path-time list sized to match).
  void finish(std::size_t file_layers);

private:
  Eigen::Matrix2d rotation_ = Eigen::Matrix2d::Identity();
};
}  // namespace scanhead
