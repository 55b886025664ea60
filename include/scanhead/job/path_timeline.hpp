/// \file path_timeline.hpp
/// \brief The exact timeline of a scan job: its segments, when each starts and how long it lasts
/// (SPEC §2.1).
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <limits>
#include <vector>

#include "scanhead/job/scan_job.hpp"

namespace scanhead
{
/// \brief One straight move of the path at constant programmed speed, or a dwell (a spot: the
/// path stays at one point for duration_s).
struct PathSegment
{
  Eigen::Vector2d start_m = Eigen::Vector2d::Zero();  ///< [m] work-plane frame
  Eigen::Vector2d end_m = Eigen::Vector2d::Zero();    ///< [m]
  double speed_mps = 0.0;                             ///< programmed speed [m/s]; 0 on a dwell
  double power_w = 0.0;                               ///< laser power [W]; 0 on jumps
  bool mark = false;                                  ///< laser on (MARK polyline)
  bool implicit_jump = false;                         ///< inserted between non-contiguous polylines
  bool dwell = false;        ///< a spot: start = end, length 0, lasts duration_s = Polyline::dwell_s
  bool delay = false;        ///< a hold the NC inserts (mark, jump or polygon delay): length 0
  bool skywriting = false;   ///< a laser-off move of skywriting (run-in, run-out, turn)
  std::size_t polyline = 0;  ///< job polyline index (implicit jump: the polyline it leads to)
  std::size_t vertex = 0;    ///< index of start_m in that polyline (implicit jump: 0)
  double length_m = 0.0;     ///< |end − start| [m], > 0 (a dwell: 0)
  double t_start_s = 0.0;    ///< prefix sum of the previous durations [s]
  double duration_s = 0.0;   ///< length / speed [s] (a dwell: its dwell time), > 0

  /// \brief The point at time \p t_s on this segment, clamped to it (the next segment's t_start_s
  /// is rounded, so a time just past this one's end stays on it).
  Eigen::Vector2d pointAt(double t_s) const
  {
    double s = (t_s - t_start_s) / duration_s;
    s = s < 0.0 ? 0.0 : (s > 1.0 ? 1.0 : s);
    return start_m + s * (end_m - start_m);
  }
};

/// \brief The job as a gapless sequence of segments starting at t = 0 at rest at its first point.
///
/// Every polyline edge of non-zero length becomes a segment at the polyline's speed (MARK:
/// laser at its power; JUMP: laser off). Where a polyline does not start where the previous one
/// ended (distance > 1e-12 m), a jump at the implicit jump speed is inserted. A polyline with
/// dwell_s > 0 (one point) becomes a dwell segment: zero length, duration dwell_s, at that point,
/// with the polyline's power (laser on if MARK); its speed is not used. Start times are the
/// prefix sums, in double and in order, of the durations (L/v, or the dwell time), so the total
/// duration is exactly Σ L/v + Σ dwell (SPEC §2.1: the remainder of a segment carries into the
/// next).
class PathTimeline
{
public:
  static constexpr double kSamePointTolerance_m = 1e-12;  ///< polylines closer than this are contiguous

  /// \brief Where to resume a search; one per monotone reader (amortised O(1) per lookup).
  struct Cursor
  {
    std::size_t segment = 0;
  };

  PathTimeline() = default;

  /// \param[in] job a job (usually validated); may be empty
  /// \param[in] implicit_jump_speed_mps speed of inserted jumps [m/s], > 0
  /// \throws InputError if a polyline's speed is not finite and > 0 (dwells excepted), a point is
  /// not finite, a dwell time is negative or not finite, or a dwell has more than one point
  /// \throws ConfigError if a jump must be inserted and \p implicit_jump_speed_mps is not > 0
  PathTimeline(const Job& job, double implicit_jump_speed_mps);

  /// \brief A timeline of given segments, in order (an NC program, nc_program.hpp): start times
  /// are recomputed as the prefix sums of the durations; the start point is the first segment's
  /// start. \throws InputError if a duration is not finite and > 0, or a segment does not start
  /// where the previous one ended (within kSamePointTolerance_m)
  static PathTimeline fromSegments(std::vector<PathSegment> segments);

  const std::vector<PathSegment>& segments() const { return segments_; }
  bool hasPoints() const { return has_points_; }                ///< false for a job without any point
  const Eigen::Vector2d& startPoint() const { return start_; }  ///< first point of the job [m]
  const Eigen::Vector2d& endPoint() const { return end_; }      ///< last point of the job [m]
  double duration() const { return duration_s_; }               ///< Σ length/speed + Σ dwell [s]

  /// \brief End time of segment \p k: the next start time, or duration() for the last one [s].
  double segmentEnd(std::size_t k) const { return k + 1 < segments_.size() ? segments_[k + 1].t_start_s : duration_s_; }

  /// \brief Index of the segment with t_start <= t < end, or npos if t < 0 or t >= duration().
  std::size_t segmentAt(double t_s, Cursor& cursor) const;

  /// \brief Point of the path at time \p t_s: the start point before 0, the end point after the
  /// end, else start + (end − start)·(t − t_start)/duration on the segment containing t.
  Eigen::Vector2d positionAt(double t_s, Cursor& cursor) const;

  /// \brief Commanded laser power at \p t_s [W]: the mark power on MARK segments, 0 on jumps,
  /// 0 before 0 and from duration() on (segments are half-open [t_start, end)).
  double powerAt(double t_s, Cursor& cursor) const;

  static constexpr std::size_t npos = std::numeric_limits<std::size_t>::max();

private:
  std::vector<PathSegment> segments_;
  Eigen::Vector2d start_ = Eigen::Vector2d::Zero();
  Eigen::Vector2d end_ = Eigen::Vector2d::Zero();
  double duration_s_ = 0.0;
  bool has_points_ = false;
};
}  // namespace scanhead
