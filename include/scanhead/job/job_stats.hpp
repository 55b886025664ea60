/// \file job_stats.hpp
/// \brief Statistics of a scan job on the NC's ideal timeline: lengths, counts, times, energy,
/// bounding box, and times per group of polylines (e.g. per square of the THESIS job).
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <string>
#include <vector>

#include "scanhead/job/scan_job.hpp"

namespace scanhead
{
/// \brief Totals of one group of polylines (a group index given per polyline).
struct JobGroupStats
{
  int group = 0;               ///< the group index
  double time_s = 0.0;         ///< Σ length/speed of its segments, leading implicit jumps included [s]
  double mark_time_s = 0.0;    ///< [s]
  double jump_time_s = 0.0;    ///< explicit and implicit jumps [s]
  double dwell_time_s = 0.0;   ///< spots (Polyline::dwell_s) [s]
  double mark_length_m = 0.0;  ///< [m]
  double jump_length_m = 0.0;  ///< [m]
};

/// \brief Statistics of a job. Segments are those of PathTimeline (SPEC §2.1): every polyline
/// edge of non-zero length, plus an implicit jump at the implicit jump speed wherever a polyline
/// does not start where the previous one ended, plus a spot for each polyline with dwell_s > 0.
/// Spots count in dwell_count / dwell_time_s (not in the mark or jump counts and times) and, if
/// MARK, in the energy.
struct JobStats
{
  std::string name;                      ///< the job's name
  double implicit_jump_speed_mps = 0.0;  ///< speed used for the implicit jumps [m/s]

  std::size_t polyline_count = 0;       ///< all polylines of the job
  std::size_t mark_polyline_count = 0;  ///< MARK polylines
  std::size_t jump_polyline_count = 0;  ///< JUMP polylines
  std::size_t mark_count = 0;           ///< MARK segments (non-zero edges of MARK polylines)
  std::size_t jump_count = 0;           ///< jump segments: explicit JUMP edges + implicit jumps
  std::size_t implicit_jump_count = 0;  ///< jumps inserted between polylines that do not join
  std::size_t dwell_count = 0;          ///< spots: polylines with dwell_s > 0

  double mark_length_m = 0.0;           ///< Σ length of MARK segments [m]
  double jump_length_m = 0.0;           ///< Σ length of explicit and implicit jumps [m]
  double implicit_jump_length_m = 0.0;  ///< the implicit part of jump_length_m [m]
  double mark_time_s = 0.0;             ///< Σ length/speed over MARK segments [s]
  double jump_time_s = 0.0;             ///< Σ length/speed over jumps [s]
  double dwell_time_s = 0.0;            ///< Σ dwell_s over spots [s]
  double ideal_time_s = 0.0;            ///< the NC timeline's duration, Σ length/speed + Σ dwell [s]
  double laser_on_energy_j = 0.0;       ///< Σ P·length/speed over MARK segments + Σ P·dwell_s over MARK spots [J]

  bool has_points = false;  ///< false for a job without any point (the boxes are then zero)
  Eigen::Vector2d bbox_min_m = Eigen::Vector2d::Zero();       ///< all points [m]
  Eigen::Vector2d bbox_max_m = Eigen::Vector2d::Zero();       ///< all points [m]
  bool has_marks = false;                                     ///< at least one MARK segment or MARK spot
  Eigen::Vector2d mark_bbox_min_m = Eigen::Vector2d::Zero();  ///< points of MARK segments and spots [m]
  Eigen::Vector2d mark_bbox_max_m = Eigen::Vector2d::Zero();  ///< points of MARK segments and spots [m]

  std::vector<JobGroupStats> groups;  ///< index = group; empty when the job is not tagged
};

/// \brief Statistics of \p job on the ideal timeline (SPEC §2.1):
/// \f[ t_{ideal} = \sum_{segments} L_k / v_k + \sum_{spots} \tau_j, \qquad
///     E_{on} = \sum_{marks} P_k L_k / v_k + \sum_{mark\ spots} P_j \tau_j \f]
/// \param[in] implicit_jump_speed_mps speed of the implicit jumps [m/s] (the NC's
///            nc.implicit_jump_speed_mps)
/// \throws InputError for a non-positive speed or a non-finite point (as PathTimeline)
/// \throws ConfigError if an implicit jump is needed and the speed is not > 0
JobStats computeJobStats(const Job& job, double implicit_jump_speed_mps);

/// \brief As above, with per-group totals: polyline p belongs to group \p group_of_polyline[p]
/// (>= 0; a negative value leaves it out of every group). An implicit jump belongs to the group
/// of the polyline it leads to.
/// \throws ConfigError if \p group_of_polyline does not have one entry per polyline
JobStats computeJobStats(const Job& job, double implicit_jump_speed_mps, const std::vector<int>& group_of_polyline);

/// \brief The statistics as YAML (keys = the JobStats member names, `groups` as a list), as printed
/// by `scanhead_job stats FILE`.
std::string jobStatsYaml(const JobStats& stats);
}  // namespace scanhead
