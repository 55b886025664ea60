/// \file job_placement.cpp
/// \brief Placement of a plate-frame job on the scan field (rotation about the plate origin, then offset).
#include "scanhead/job/job_placement.hpp"

#include <cmath>

#include "scanhead/common/errors.hpp"
#include "scanhead/common/number_text.hpp"
#include "scanhead/job/cam_config.hpp"
#include "scanhead/job/scan_job.hpp"

namespace scanhead
{
Eigen::Matrix2d placementRotation(double degrees)
{
  // Exact for the quarter turns a machine uses most (cos 90° is not 0 in floating point).
  const double turns = degrees / 90.0;
  if (turns == std::round(turns))
  {
    const int q = ((static_cast<int>(turns) % 4) + 4) % 4;
    const double c[4] = {1.0, 0.0, -1.0, 0.0}, s[4] = {0.0, 1.0, 0.0, -1.0};
    Eigen::Matrix2d r;
    r << c[q], -s[q], s[q], c[q];
    return r;
  }
  const double a = degrees * M_PI / 180.0;
  Eigen::Matrix2d r;
  r << std::cos(a), -std::sin(a), std::sin(a), std::cos(a);
  return r;
}

std::string JobPlacement::yaml() const
{
  return "{rotation_deg: " + fullPrecisionText(rotation_deg) + ", offset_m: [" + fullPrecisionText(offset_m.x()) +
         ", " + fullPrecisionText(offset_m.y()) + "], centred: " + (centred ? "true" : "false") + "}";
}

bool rotatedBoundingBox(const Job& job, double rotation_deg, Eigen::Vector2d& lo, Eigen::Vector2d& hi)
{
  const Eigen::Matrix2d r = placementRotation(rotation_deg);
  bool any = false;
  for (const Polyline& line : job.polylines)
    for (const Eigen::Vector2d& p : line.points)
    {
      const Eigen::Vector2d q = r * p;
      lo = any ? lo.cwiseMin(q) : q;
      hi = any ? hi.cwiseMax(q) : q;
      any = true;
    }
  return any;
}

JobPlacement placementFor(const CamConfig& cam, const Job& job)
{
  JobPlacement placement;
  placement.rotation_deg = cam.rotation_deg;
  placement.offset_m = Eigen::Vector2d(cam.offset_m[0], cam.offset_m[1]);
  if (cam.centre)
  {
    Eigen::Vector2d lo = job.file.box_lo, hi = job.file.box_hi;
    const bool surveyed = job.file.surveyed && job.file.box_rotation_deg == cam.rotation_deg;
    if (!(surveyed ? job.file.has_points : rotatedBoundingBox(job, cam.rotation_deg, lo, hi)))
      throw InputError(job.source + ": cam.centre: the job has no point to centre");
    placement.offset_m -= 0.5 * (lo + hi);
    placement.centred = true;
  }
  return placement;
}

void placeJob(Job& job, const JobPlacement& placement)
{
  if (placement.identity())
  {
    job.placement.centred = job.placement.centred || placement.centred;
    return;  // the points bit for bit as read
  }
  const Eigen::Matrix2d r = placementRotation(placement.rotation_deg);
  for (Polyline& line : job.polylines)
    for (Eigen::Vector2d& p : line.points)
      p = r * p + placement.offset_m;
  // Composed with what the job carried (a job.yaml written by a placed run): p → R2(R1 p + o1) + o2.
  job.placement.offset_m = r * job.placement.offset_m + placement.offset_m;
  job.placement.rotation_deg += placement.rotation_deg;
  job.placement.centred = job.placement.centred || placement.centred;
}
}  // namespace scanhead
