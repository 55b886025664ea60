/// \file path_timeline.cpp
/// \brief The exact timeline of a scan job (SPEC §2.1).
#include "scanhead/job/path_timeline.hpp"

#include <cmath>
#include <sstream>
#include <utility>

#include "scanhead/common/errors.hpp"

namespace scanhead
{
namespace
{
void appendSegment(std::vector<PathSegment>& segments, double& t_s, PathSegment seg)
{
  seg.length_m = (seg.end_m - seg.start_m).norm();
  if (!(seg.length_m > 0.0))
  {
    return;  // zero-length segments take no time and are skipped
  }
  seg.duration_s = seg.length_m / seg.speed_mps;
  seg.t_start_s = t_s;
  t_s += seg.duration_s;
  segments.push_back(seg);
}
}  // namespace

PathTimeline::PathTimeline(const Job& job, double implicit_jump_speed_mps)
{
  double t_s = 0.0;
  Eigen::Vector2d current = Eigen::Vector2d::Zero();
  for (std::size_t p = 0; p < job.polylines.size(); ++p)
  {
    const Polyline& line = job.polylines[p];
    if (line.points.empty())
    {
      continue;
    }
    if (!(std::isfinite(line.dwell_s) && line.dwell_s >= 0.0))
    {
      std::ostringstream msg;
      msg << "job '" << job.name << "': polyline " << p << " dwell_s must be >= 0 (got " << line.dwell_s << ")";
      throw InputError(msg.str());
    }
    const bool dwell = line.dwell_s > 0.0;
    if (dwell && line.points.size() != 1)
    {
      std::ostringstream msg;
      msg << "job '" << job.name << "': polyline " << p << " is a dwell: it needs exactly 1 point (got "
          << line.points.size() << ")";
      throw InputError(msg.str());
    }
    if (!dwell && !(std::isfinite(line.speed_mps) && line.speed_mps > 0.0))
    {
      std::ostringstream msg;
      msg << "job '" << job.name << "': polyline " << p << " speed_mps must be > 0 (got " << line.speed_mps << ")";
      throw InputError(msg.str());
    }
    for (std::size_t v = 0; v < line.points.size(); ++v)
    {
      if (!line.points[v].allFinite())
      {
        std::ostringstream msg;
        msg << "job '" << job.name << "': polyline " << p << " point " << v << " is not finite";
        throw InputError(msg.str());
      }
    }
    if (!has_points_)
    {
      start_ = line.points.front();
      current = start_;
      has_points_ = true;
    }
    else if ((line.points.front() - current).norm() > kSamePointTolerance_m)
    {
      if (!(std::isfinite(implicit_jump_speed_mps) && implicit_jump_speed_mps > 0.0))
      {
        std::ostringstream msg;
        msg << "nc.implicit_jump_speed_mps must be > 0 (got " << implicit_jump_speed_mps << ")";
        throw ConfigError(msg.str());
      }
      PathSegment jump;
      jump.start_m = current;
      jump.end_m = line.points.front();
      jump.speed_mps = implicit_jump_speed_mps;
      jump.implicit_jump = true;
      jump.polyline = p;
      appendSegment(segments_, t_s, jump);
    }
    const bool mark = (line.type == PolylineType::Mark);
    if (dwell)
    {
      // A spot: zero length, lasts dwell_s, at the polyline's power (the laser gate reads it).
      PathSegment seg;
      seg.start_m = line.points.front();
      seg.end_m = line.points.front();
      seg.mark = mark;
      seg.power_w = mark ? line.power_w : 0.0;
      seg.dwell = true;
      seg.polyline = p;
      seg.duration_s = line.dwell_s;
      seg.t_start_s = t_s;
      t_s += seg.duration_s;
      segments_.push_back(seg);
    }
    for (std::size_t v = 0; v + 1 < line.points.size(); ++v)
    {
      PathSegment seg;
      seg.start_m = line.points[v];
      seg.end_m = line.points[v + 1];
      seg.speed_mps = line.speed_mps;
      seg.mark = mark;
      seg.power_w = mark ? line.power_w : 0.0;
      seg.polyline = p;
      seg.vertex = v;
      appendSegment(segments_, t_s, seg);
    }
    current = line.points.back();
  }
  end_ = current;
  duration_s_ = t_s;
}

PathTimeline PathTimeline::fromSegments(std::vector<PathSegment> segments)
{
  // Same prefix sums, in the same order, as the Job constructor: a job's own segments give back
  // bit-identical start times and duration.
  PathTimeline timeline;
  double t_s = 0.0;
  for (std::size_t k = 0; k < segments.size(); ++k)
  {
    PathSegment& seg = segments[k];
    if (!(std::isfinite(seg.duration_s) && seg.duration_s > 0.0))
    {
      std::ostringstream msg;
      msg << "path segment " << k << " duration_s must be > 0 (got " << seg.duration_s << ")";
      throw InputError(msg.str());
    }
    if (!seg.start_m.allFinite() || !seg.end_m.allFinite())
    {
      std::ostringstream msg;
      msg << "path segment " << k << " has a point that is not finite";
      throw InputError(msg.str());
    }
    if (k > 0)
    {
      const double gap_m = (seg.start_m - segments[k - 1].end_m).norm();
      if (!(gap_m <= kSamePointTolerance_m))
      {
        std::ostringstream msg;
        msg << "path segment " << k << " starts " << gap_m << " m from where segment " << (k - 1)
            << " ended (tolerance " << kSamePointTolerance_m << " m)";
        throw InputError(msg.str());
      }
    }
    seg.t_start_s = t_s;
    t_s += seg.duration_s;
  }
  if (!segments.empty())
  {
    timeline.start_ = segments.front().start_m;
    timeline.end_ = segments.back().end_m;
    timeline.has_points_ = true;
  }
  timeline.duration_s_ = t_s;
  timeline.segments_ = std::move(segments);
  return timeline;
}

std::size_t PathTimeline::segmentAt(double t_s, Cursor& cursor) const
{
  if (!(t_s >= 0.0) || !(t_s < duration_s_) || segments_.empty())
  {
    return npos;
  }
  std::size_t k = cursor.segment < segments_.size() ? cursor.segment : segments_.size() - 1;
  while (k > 0 && t_s < segments_[k].t_start_s)
  {
    --k;  // only for non-monotone readers
  }
  while (k + 1 < segments_.size() && t_s >= segments_[k + 1].t_start_s)
  {
    ++k;
  }
  cursor.segment = k;
  return k;
}

Eigen::Vector2d PathTimeline::positionAt(double t_s, Cursor& cursor) const
{
  if (!(t_s > 0.0))
  {
    return start_;
  }
  const std::size_t k = segmentAt(t_s, cursor);
  if (k == npos)
  {
    return end_;
  }
  return segments_[k].pointAt(t_s);
}

double PathTimeline::powerAt(double t_s, Cursor& cursor) const
{
  const std::size_t k = segmentAt(t_s, cursor);
  if (k == npos)
  {
    return 0.0;
  }
  const PathSegment& seg = segments_[k];
  return seg.mark ? seg.power_w : 0.0;
}
}  // namespace scanhead
