/// \file scan_job.hpp
/// \brief The CAM scan path: polylines in the work-plane frame, each MARK or JUMP.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "scanhead/job/file_survey.hpp"
#include "scanhead/job/job_placement.hpp"

namespace scanhead
{
enum class PolylineType
{
  Mark,  ///< laser on along the polyline
  Jump   ///< laser off, mirrors repositioning
};

/// \brief What a MARK polyline draws, for recipes that set contour and hatch speeds apart.
enum class PolylineRole
{
  Unspecified,  ///< the recipe treats it as hatch
  Contour,      ///< part outline (CLI $$POLYLINE)
  Hatch         ///< infill (CLI $$HATCHES)
};

struct Polyline
{
  PolylineType type = PolylineType::Mark;
  PolylineRole role = PolylineRole::Unspecified;  ///< MARK only; jumps ignore it
  double speed_mps = 1.0;                         ///< programmed tangential speed [m/s], > 0 (unused by a dwell)
  double power_w = 0.0;                           ///< laser power while marking [W], >= 0 (ignored on jumps)
  std::vector<Eigen::Vector2d> points;            ///< vertices [m], work-plane frame, at least 2 (a dwell: exactly 1)
  double dwell_s = 0.0;  ///< a spot: laser at this point for this long [s] (one point, MARK); 0: a line
};

/// \brief A scan job (the message scanhead/ScanJob carries the same on cam/job).
struct Job
{
  std::string name;    ///< short identifier, used in reports
  std::string source;  ///< where it came from (file path or built-in description)
  std::vector<Polyline> polylines;
  JobPlacement placement;  ///< how the file's points were moved onto the field (identity: as read)
  FileSurvey file;  ///< the file it was read from, every layer (CLI, segment files; others: 1 layer, not surveyed)
};

/// \brief A direction change inside a MARK polyline (vertex i of polyline p).
struct Corner
{
  std::size_t polyline = 0;
  std::size_t vertex = 0;
  Eigen::Vector2d point = Eigen::Vector2d::Zero();  ///< commanded corner [m]
  double angle_rad = 0.0;                           ///< direction change gamma (0 = straight on)
  double speed_mps = 0.0;                           ///< programmed speed of the polyline
  double time_s = 0.0;                              ///< time the ideal timeline reaches the corner [s]
  double window_in_s = 0.0;                         ///< half the duration of the incoming segment [s]
  double window_out_s = 0.0;                        ///< half the duration of the outgoing segment [s]
};

/// \brief Corners of more than \p min_angle_rad inside MARK polylines, with their ideal times.
/// \param[in] job  a validated job
/// \param[in] implicit_jump_speed_mps speed of the jumps inserted between non-contiguous polylines
std::vector<Corner> findCorners(const Job& job, double min_angle_rad, double implicit_jump_speed_mps);

class PathTimeline;
/// \brief Corners of an NC program's timeline (nc_program.hpp): as above, where a polygon-delay
/// hold between two edges of a mark does not break the corner (its time is the hold's end);
/// skywritten corners are not corners any more (laser-off moves between the edges).
std::vector<Corner> findCorners(const PathTimeline& timeline, double min_angle_rad);
}  // namespace scanhead
