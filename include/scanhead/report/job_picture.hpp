/// \file job_picture.hpp
/// \brief A picture of a scan job: marks and jumps in two colours on white, aspect kept.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <string>

#include "scanhead/job/scan_job.hpp"
#include "scanhead/report/image.hpp"

namespace scanhead
{
/// \brief Drawing options; the defaults are those of renderJobPicture(job, max_side_px).
struct JobPictureOptions
{
  int margin_px = -1;                                     ///< blank border [px]; < 0: max(2, max_side_px / 40)
  bool show_jumps = true;                                 ///< draw explicit and implicit jumps
  bool show_start_points = false;                         ///< a dot at the first point of every MARK polyline
  double mark_width_px = 1.5;                             ///< line width of marks [px]
  double jump_width_px = 1.0;                             ///< line width of jumps [px]
  double jump_dash_px = 4.0;                              ///< drawn length of a jump dash [px]; <= 0: solid
  double jump_gap_px = 3.0;                               ///< gap between jump dashes [px]
  std::array<std::uint8_t, 3> mark_rgb{{20, 40, 150}};    ///< dark blue
  std::array<std::uint8_t, 3> jump_rgb{{170, 170, 170}};  ///< light grey
  std::array<std::uint8_t, 3> start_rgb{{0, 150, 60}};    ///< green
};

/// \brief Work-plane metres to pixels of a job picture (pixel centres at integer coordinates,
/// y up in the plane, down in the image).
/// \f[ p_x = m + (x - x_{min})\,s, \qquad p_y = (H - 1 - m) - (y - y_{min})\,s,
///     \qquad s = \frac{N - 1 - 2m}{\max(x_{max} - x_{min},\ y_{max} - y_{min})} \f]
/// with N = max_side_px and m the margin; the longer side of the picture is N pixels.
struct JobPictureFrame
{
  int width = 0;                                    ///< [px]
  int height = 0;                                   ///< [px]
  int margin_px = 0;                                ///< [px]
  double scale_px_per_m = 1.0;                      ///< s [px/m]
  Eigen::Vector2d min_m = Eigen::Vector2d::Zero();  ///< lower-left corner of the job's bounding box [m]

  Eigen::Vector2d toPixel(const Eigen::Vector2d& p_m) const
  {
    return Eigen::Vector2d(margin_px + (p_m.x() - min_m.x()) * scale_px_per_m,
                           (height - 1 - margin_px) - (p_m.y() - min_m.y()) * scale_px_per_m);
  }
};

/// \brief The frame renderJobPicture uses for \p job (bounding box of all points; a job without
/// extent gets a 1 mm box around its point, an empty job a square picture).
/// \throws ConfigError unless 16 <= max_side_px <= 8192 and the margin leaves room to draw
JobPictureFrame jobPictureFrame(const Job& job, int max_side_px, int margin_px);

/// \brief Marks (dark blue, 1.5 px) over jumps (light grey, 1 px, dashed; implicit jumps between
/// polylines that do not join included) on white, anti-aliased by the distance of each pixel
/// centre to the segment: coverage = clamp(width/2 + 1/2 − d, 0, 1), the maximum over segments.
/// MARK spots (dwell_s > 0) are dots in the mark colour.
/// \throws ConfigError as jobPictureFrame
RgbImage renderJobPicture(const Job& job, int max_side_px);
RgbImage renderJobPicture(const Job& job, int max_side_px, const JobPictureOptions& options);

/// \brief writePng(path, renderJobPicture(job, max_side_px)).
void writeJobPicture(const std::string& path, const Job& job, int max_side_px);
}  // namespace scanhead
