/// \file scan_job.cpp
/// \brief Corners of a scan job, timed on the same timeline as the NC (SPEC §2.1, §2.3).
#include "scanhead/job/scan_job.hpp"

#include <cmath>

#include "scanhead/job/path_timeline.hpp"

namespace scanhead
{
std::vector<Corner> findCorners(const Job& job, double min_angle_rad, double implicit_jump_speed_mps)
{
  // The NC's own timeline (implicit jumps included, zero-length edges skipped), so time_s is
  // exactly when the NC's X_inter passes the vertex.
  return findCorners(PathTimeline(job, implicit_jump_speed_mps), min_angle_rad);
}

std::vector<Corner> findCorners(const PathTimeline& timeline, double min_angle_rad)
{
  // A corner joins two consecutive non-zero edges of the same MARK polyline (polygon holds in
  // between are skipped); with repeated points, vertex is the start of the outgoing edge.
  // Dwells (spots, zero length) have no direction: never a corner.
  const std::vector<PathSegment>& segs = timeline.segments();
  std::vector<Corner> corners;
  const PathSegment* in = nullptr;
  for (std::size_t k = 0; k < segs.size(); ++k)
  {
    const PathSegment& out = segs[k];
    if (out.delay && out.mark && out.length_m == 0.0)
    {
      continue;  // a polygon hold: the mark goes on after it
    }
    const PathSegment* previous = in;
    in = &out;
    if (previous == nullptr || !previous->mark || !out.mark || previous->implicit_jump || out.implicit_jump ||
        previous->dwell || out.dwell || previous->delay || out.delay || previous->skywriting || out.skywriting ||
        previous->polyline != out.polyline)
    {
      continue;
    }
    const Eigen::Vector2d d_in = (previous->end_m - previous->start_m) / previous->length_m;
    const Eigen::Vector2d d_out = (out.end_m - out.start_m) / out.length_m;
    const double cross = d_in.x() * d_out.y() - d_in.y() * d_out.x();
    const double gamma = std::atan2(std::abs(cross), d_in.dot(d_out));  // direction change in [0, π]
    if (!(gamma > min_angle_rad))
    {
      continue;
    }
    Corner c;
    c.polyline = out.polyline;
    c.vertex = out.vertex;
    c.point = out.start_m;
    c.angle_rad = gamma;
    c.speed_mps = out.speed_mps;
    c.time_s = out.t_start_s;
    c.window_in_s = 0.5 * previous->duration_s;
    c.window_out_s = 0.5 * out.duration_s;
    corners.push_back(c);
  }
  return corners;
}
}  // namespace scanhead
