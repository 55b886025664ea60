/// \file job_stats.cpp
/// \brief Job statistics on the NC's ideal timeline (SPEC §2.1).
#include "scanhead/job/job_stats.hpp"

#include <cstdio>
#include <sstream>

#include "scanhead/common/config_check.hpp"
#include "scanhead/common/number_text.hpp"
#include "scanhead/job/path_timeline.hpp"

namespace scanhead
{
namespace
{
void grow(bool& has, Eigen::Vector2d& lo, Eigen::Vector2d& hi, const Eigen::Vector2d& p)
{
  if (!has)
  {
    lo = p;
    hi = p;
    has = true;
    return;
  }
  lo = lo.cwiseMin(p);
  hi = hi.cwiseMax(p);
}

JobStats compute(const Job& job, double implicit_jump_speed_mps, const std::vector<int>* group_of_polyline)
{
  JobStats s;
  s.name = job.name;
  s.implicit_jump_speed_mps = implicit_jump_speed_mps;
  s.polyline_count = job.polylines.size();
  for (const Polyline& line : job.polylines)
  {
    (line.type == PolylineType::Mark ? s.mark_polyline_count : s.jump_polyline_count) += 1;
    for (const Eigen::Vector2d& p : line.points)
    {
      grow(s.has_points, s.bbox_min_m, s.bbox_max_m, p);
    }
  }

  const PathTimeline timeline(job, implicit_jump_speed_mps);
  if (group_of_polyline != nullptr)
  {
    int max_group = -1;
    for (int g : *group_of_polyline)
    {
      max_group = g > max_group ? g : max_group;
    }
    s.groups.resize(static_cast<std::size_t>(max_group + 1));
    for (std::size_t g = 0; g < s.groups.size(); ++g)
    {
      s.groups[g].group = static_cast<int>(g);
    }
  }
  for (const PathSegment& seg : timeline.segments())
  {
    JobGroupStats* group = nullptr;
    if (group_of_polyline != nullptr && (*group_of_polyline)[seg.polyline] >= 0)
    {
      group = &s.groups[static_cast<std::size_t>((*group_of_polyline)[seg.polyline])];
    }
    if (seg.dwell)
    {
      ++s.dwell_count;
      s.dwell_time_s += seg.duration_s;
      if (seg.mark)
      {
        s.laser_on_energy_j += seg.power_w * seg.duration_s;
        grow(s.has_marks, s.mark_bbox_min_m, s.mark_bbox_max_m, seg.start_m);
      }
      if (group != nullptr)
      {
        group->dwell_time_s += seg.duration_s;
        group->time_s += seg.duration_s;
      }
    }
    else if (seg.mark)
    {
      ++s.mark_count;
      s.mark_length_m += seg.length_m;
      s.mark_time_s += seg.duration_s;
      s.laser_on_energy_j += seg.power_w * seg.duration_s;
      grow(s.has_marks, s.mark_bbox_min_m, s.mark_bbox_max_m, seg.start_m);
      grow(s.has_marks, s.mark_bbox_min_m, s.mark_bbox_max_m, seg.end_m);
      if (group != nullptr)
      {
        group->mark_length_m += seg.length_m;
        group->mark_time_s += seg.duration_s;
        group->time_s += seg.duration_s;
      }
    }
    else
    {
      ++s.jump_count;
      s.jump_length_m += seg.length_m;
      s.jump_time_s += seg.duration_s;
      if (seg.implicit_jump)
      {
        ++s.implicit_jump_count;
        s.implicit_jump_length_m += seg.length_m;
      }
      if (group != nullptr)
      {
        group->jump_length_m += seg.length_m;
        group->jump_time_s += seg.duration_s;
        group->time_s += seg.duration_s;
      }
    }
  }
  s.ideal_time_s = timeline.duration();
  return s;
}

/// Shortest text that reads back to the same double (YAML plain scalar), from 10 significant
/// digits on so that round numbers stay out of exponent form.
std::string num(double v)
{
  return shortestText(v, 10);
}

/// YAML double-quoted string.
std::string quoted(const std::string& text)
{
  std::string out = "\"";
  for (unsigned char c : text)
  {
    if (c == '"' || c == '\\')
    {
      out += '\\';
      out += static_cast<char>(c);
    }
    else if (c < 0x20 || c == 0x7f)
    {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\x%02x", c);
      out += buf;
    }
    else
    {
      out += static_cast<char>(c);
    }
  }
  return out + "\"";
}

std::string point(const Eigen::Vector2d& p)
{
  return "[" + num(p.x()) + ", " + num(p.y()) + "]";
}
}  // namespace

JobStats computeJobStats(const Job& job, double implicit_jump_speed_mps)
{
  return compute(job, implicit_jump_speed_mps, nullptr);
}

JobStats computeJobStats(const Job& job, double implicit_jump_speed_mps, const std::vector<int>& group_of_polyline)
{
  if (group_of_polyline.size() != job.polylines.size())
  {
    failSetting("group_of_polyline.size", "== the job's polyline count " + std::to_string(job.polylines.size()),
                static_cast<double>(group_of_polyline.size()));
  }
  return compute(job, implicit_jump_speed_mps, &group_of_polyline);
}

std::string jobStatsYaml(const JobStats& s)
{
  std::ostringstream out;
  out << "name: " << quoted(s.name) << "\n";
  out << "implicit_jump_speed_mps: " << num(s.implicit_jump_speed_mps) << "\n";
  out << "polyline_count: " << s.polyline_count << "\n";
  out << "mark_polyline_count: " << s.mark_polyline_count << "\n";
  out << "jump_polyline_count: " << s.jump_polyline_count << "\n";
  out << "mark_count: " << s.mark_count << "\n";
  out << "jump_count: " << s.jump_count << "\n";
  out << "implicit_jump_count: " << s.implicit_jump_count << "\n";
  out << "dwell_count: " << s.dwell_count << "\n";
  out << "mark_length_m: " << num(s.mark_length_m) << "\n";
  out << "jump_length_m: " << num(s.jump_length_m) << "\n";
  out << "implicit_jump_length_m: " << num(s.implicit_jump_length_m) << "\n";
  out << "mark_time_s: " << num(s.mark_time_s) << "\n";
  out << "jump_time_s: " << num(s.jump_time_s) << "\n";
  out << "dwell_time_s: " << num(s.dwell_time_s) << "\n";
  out << "ideal_time_s: " << num(s.ideal_time_s) << "\n";
  out << "laser_on_energy_j: " << num(s.laser_on_energy_j) << "\n";
  if (s.has_points)
  {
    out << "bbox_min_m: " << point(s.bbox_min_m) << "\n";
    out << "bbox_max_m: " << point(s.bbox_max_m) << "\n";
  }
  if (s.has_marks)
  {
    out << "mark_bbox_min_m: " << point(s.mark_bbox_min_m) << "\n";
    out << "mark_bbox_max_m: " << point(s.mark_bbox_max_m) << "\n";
  }
  if (!s.groups.empty())
  {
    out << "groups:\n";
    for (const JobGroupStats& g : s.groups)
    {
      out << "  - {group: " << g.group << ", time_s: " << num(g.time_s) << ", mark_time_s: " << num(g.mark_time_s)
          << ", jump_time_s: " << num(g.jump_time_s) << ", dwell_time_s: " << num(g.dwell_time_s)
          << ", mark_length_m: " << num(g.mark_length_m) << ", jump_length_m: " << num(g.jump_length_m) << "}\n";
    }
  }
  return out.str();
}
}  // namespace scanhead
