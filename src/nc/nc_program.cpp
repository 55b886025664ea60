/// \file nc_program.cpp
/// \brief The program the NC runs: recipe, speed cap, mark/jump/polygon delays, skywriting, and
/// the laser gate on it (SPEC §2.5).
#include "scanhead/nc/nc_program.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "scanhead/common/config_check.hpp"

namespace scanhead
{
namespace
{
constexpr double kPi = 3.14159265358979323846;

/// What a run of consecutive timeline segments is.
enum class GroupKind
{
  ImplicitJump,  ///< a jump PathTimeline inserted (one segment)
  Jump,          ///< the moves of one JUMP polyline
  Mark,          ///< the moves of one MARK polyline
  Dwell          ///< a spot (one segment), MARK or JUMP
};

/// Segments [begin, end) of the recipe's timeline that come from one polyline (or one implicit jump).
struct Group
{
  GroupKind kind = GroupKind::Mark;
  std::size_t begin = 0;
  std::size_t end = 0;
};

GroupKind kindOf(const PathSegment& seg)
{
  if (seg.implicit_jump)
    return GroupKind::ImplicitJump;
  if (seg.dwell)
    return GroupKind::Dwell;
  return seg.mark ? GroupKind::Mark : GroupKind::Jump;
}

std::vector<Group> groupSegments(const std::vector<PathSegment>& segs)
{
  std::vector<Group> groups;
  for (std::size_t k = 0; k < segs.size(); ++k)
  {
    const GroupKind kind = kindOf(segs[k]);
    const bool single = kind == GroupKind::ImplicitJump || kind == GroupKind::Dwell;
    if (!single && !groups.empty() && groups.back().kind == kind &&
        segs[groups.back().begin].polyline == segs[k].polyline)
    {
      groups.back().end = k + 1;
    }
    else
    {
      groups.push_back(Group{kind, k, k + 1});
    }
  }
  return groups;
}

void validateOptions(const NcProgramOptions& o)
{
  requireSetting(o.mark_delay_s >= 0.0, "nc.mark_delay_s", ">= 0", o.mark_delay_s);
  requireSetting(o.jump_delay_s >= 0.0, "nc.jump_delay_s", ">= 0", o.jump_delay_s);
  requireSetting(o.polygon_delay_s >= 0.0, "nc.polygon_delay_s", ">= 0", o.polygon_delay_s);
  if (!(o.speed_cap_mps > 0.0))
  {
    failSetting("nc_program.speed_cap_mps", "> 0", o.speed_cap_mps);  // +inf: no cap
  }
  const Recipe& r = o.recipe;
  requireSetting(std::isfinite(r.laser_on_delay_s), "recipe.laser_on_delay_s", "finite", r.laser_on_delay_s);
  requireSetting(std::isfinite(r.laser_off_delay_s), "recipe.laser_off_delay_s", "finite", r.laser_off_delay_s);
  if (r.override_job)
  {
    requireSetting(r.contour_speed_mps > 0.0, "recipe.contour_speed_mps", "> 0", r.contour_speed_mps);
    requireSetting(r.hatch_speed_mps > 0.0, "recipe.hatch_speed_mps", "> 0", r.hatch_speed_mps);
    requireSetting(r.jump_speed_mps > 0.0, "recipe.jump_speed_mps", "> 0", r.jump_speed_mps);
    requireSetting(r.contour_jump_speed_mps > 0.0, "recipe.contour_jump_speed_mps", "> 0", r.contour_jump_speed_mps);
    requireSetting(r.contour_power_w >= 0.0, "recipe.contour_power_w", ">= 0", r.contour_power_w);
    requireSetting(r.hatch_power_w >= 0.0, "recipe.hatch_power_w", ">= 0", r.hatch_power_w);
  }
  if (o.skywriting.enabled)
  {
    o.skywriting.validate();
  }
}

/// Unit direction of a move (length_m > 0).
Eigen::Vector2d directionOf(const PathSegment& seg)
{
  return (seg.end_m - seg.start_m) / seg.length_m;
}

/// Appends the program's segments; keeps where the path is.
class ProgramWriter
{
public:
  std::vector<PathSegment> segments;
  Eigen::Vector2d at_m = Eigen::Vector2d::Zero();  ///< end of the last segment [m]

  /// A segment of the recipe's timeline, unchanged (its length and duration bit for bit).
  void keep(const PathSegment& seg)
  {
    segments.push_back(seg);
    at_m = seg.end_m;
  }

  /// A straight move with \p seg's flags at seg.speed_mps: length and duration recomputed as the
  /// PathTimeline does (|end − start|, then L/v); zero-length moves are skipped.
  bool move(PathSegment seg)
  {
    seg.length_m = (seg.end_m - seg.start_m).norm();
    if (!(seg.length_m > 0.0))
    {
      return false;
    }
    seg.duration_s = seg.length_m / seg.speed_mps;
    segments.push_back(seg);
    at_m = seg.end_m;
    return true;
  }

  /// A laser-off skywriting move (run-in, run-out, turn or the link between two marks).
  bool skyMove(const Eigen::Vector2d& from, const Eigen::Vector2d& to, double speed_mps, std::size_t polyline,
               std::size_t vertex)
  {
    PathSegment seg;
    seg.start_m = from;
    seg.end_m = to;
    seg.speed_mps = speed_mps;
    seg.skywriting = true;
    seg.polyline = polyline;
    seg.vertex = vertex;
    return move(seg);
  }

  /// A hold at the current point (none if the duration is not > 0).
  bool hold(double duration_s, bool mark, double power_w, double speed_mps, std::size_t polyline, std::size_t vertex)
  {
    if (!(duration_s > 0.0))
    {
      return false;
    }
    PathSegment seg;
    seg.start_m = at_m;
    seg.end_m = at_m;
    seg.speed_mps = speed_mps;
    seg.power_w = power_w;
    seg.mark = mark;
    seg.delay = true;
    seg.polyline = polyline;
    seg.vertex = vertex;
    seg.duration_s = duration_s;
    segments.push_back(seg);
    return true;
  }
};

/// Turns the recipe's timeline into the program, group by group.
class ProgramBuilder
{
public:
  ProgramBuilder(const std::vector<PathSegment>& segs, const NcProgramOptions& options, NcProgramStats& stats)
    : segs_(segs)
    , groups_(groupSegments(segs))
    , options_(options)
    , stats_(stats)
    , sky_(options.skywriting.enabled)
    , min_angle_rad_(options.skywriting.min_angle_deg * kPi / 180.0)
  {
  }

  std::vector<PathSegment> build()
  {
    if (!groups_.empty())
    {
      out_.at_m = entry(0);
    }
    for (std::size_t g = 0; g < groups_.size(); ++g)
    {
      switch (groups_[g].kind)
      {
        case GroupKind::ImplicitJump:
        case GroupKind::Jump:
          emitJump(g);
          break;
        case GroupKind::Dwell:
          link(g);
          out_.keep(segs_[groups_[g].begin]);
          break;
        case GroupKind::Mark:
          link(g);
          emitMark(g);
          break;
      }
    }
    return std::move(out_.segments);
  }

private:
  double runIn(double v_mps) const { return options_.skywriting.run_in_m + options_.skywriting.run_in_s * v_mps; }
  double runOut(double v_mps) const { return options_.skywriting.run_out_m + options_.skywriting.run_out_s * v_mps; }

  /// Where group \p g starts in the program: a skywritten mark at its run-in start.
  Eigen::Vector2d entry(std::size_t g) const
  {
    const PathSegment& first = segs_[groups_[g].begin];
    if (sky_ && groups_[g].kind == GroupKind::Mark)
    {
      const double run_in_m = runIn(first.speed_mps);
      if (run_in_m > 0.0)
      {
        return first.start_m - directionOf(first) * run_in_m;
      }
    }
    return first.start_m;
  }

  /// Jumps start where the program is and end where the next mark or dwell starts (a skywritten
  /// mark's run-in start); a jump delay follows each jump that moved.
  void emitJump(std::size_t g)
  {
    const Group& grp = groups_[g];
    const bool into_work =
        g + 1 < groups_.size() && (groups_[g + 1].kind == GroupKind::Mark || groups_[g + 1].kind == GroupKind::Dwell);
    const Eigen::Vector2d target = into_work ? entry(g + 1) : segs_[grp.end - 1].end_m;
    bool moved = false;
    for (std::size_t k = grp.begin; k < grp.end; ++k)
    {
      PathSegment seg = segs_[k];
      if (k == grp.begin)
        seg.start_m = out_.at_m;
      if (k + 1 == grp.end)
        seg.end_m = target;
      moved = out_.move(seg) || moved;
    }
    const PathSegment& last = segs_[grp.end - 1];
    if (moved && out_.hold(options_.jump_delay_s, false, 0.0, 0.0, last.polyline, last.vertex))
    {
      ++stats_.delay_holds;
    }
  }

  /// Without a jump before it, a mark or dwell may not start where the program is (the previous
  /// mark's run-out, or this mark's run-in start): a laser-off skywriting move links them, at the
  /// speed of the mark involved (this one, else the previous one).
  void link(std::size_t g)
  {
    const Eigen::Vector2d target = entry(g);
    if (!((out_.at_m - target).norm() > PathTimeline::kSamePointTolerance_m))
    {
      return;
    }
    const PathSegment& first = segs_[groups_[g].begin];
    double speed_mps = options_.implicit_jump_speed_mps;
    if (groups_[g].kind == GroupKind::Mark)
      speed_mps = first.speed_mps;
    else if (g > 0 && groups_[g - 1].kind == GroupKind::Mark)
      speed_mps = segs_[groups_[g - 1].begin].speed_mps;
    out_.skyMove(out_.at_m, target, speed_mps, first.polyline, first.vertex);
  }

  void emitMark(std::size_t g)
  {
    const Group& grp = groups_[g];
    const PathSegment& first = segs_[grp.begin];
    const PathSegment& last = segs_[grp.end - 1];
    const double v_mps = first.speed_mps;
    const double run_in_m = sky_ ? runIn(v_mps) : 0.0;
    const double run_out_m = sky_ ? runOut(v_mps) : 0.0;
    if (sky_)
    {
      out_.skyMove(entry(g), first.start_m, v_mps, first.polyline, first.vertex);
    }
    out_.keep(first);
    for (std::size_t k = grp.begin + 1; k < grp.end; ++k)
    {
      const PathSegment& in = segs_[k - 1];
      const PathSegment& seg = segs_[k];
      const Eigen::Vector2d d_in = directionOf(in);
      const Eigen::Vector2d d_out = directionOf(seg);
      const double cross = d_in.x() * d_out.y() - d_in.y() * d_out.x();
      const double gamma_rad = std::atan2(std::abs(cross), d_in.dot(d_out));  // direction change in [0, π]
      const Eigen::Vector2d& corner = seg.start_m;
      // Below 1 µrad a vertex is straight (rounding of collinear points gives ~1e-15 rad).
      constexpr double kStraight_rad = 1e-6;
      // (zero run lengths: nothing to skywrite, the corner keeps its polygon hold)
      if (sky_ && run_in_m + run_out_m > 0.0 && gamma_rad > std::max(min_angle_rad_, kStraight_rad))
      {
        // run-out along the incoming direction, turn, run-in back to the corner: laser off
        const Eigen::Vector2d out_end = corner + d_in * run_out_m;
        const Eigen::Vector2d in_start = corner - d_out * run_in_m;
        out_.skyMove(corner, out_end, v_mps, seg.polyline, seg.vertex);
        out_.skyMove(out_end, in_start, v_mps, seg.polyline, seg.vertex);
        out_.skyMove(in_start, corner, v_mps, seg.polyline, seg.vertex);
        ++stats_.skywritten_corners;
      }
      else if (gamma_rad > kStraight_rad)
      {
        const double hold_s =
            options_.polygon_delay_by_angle ? options_.polygon_delay_s * (gamma_rad / kPi) : options_.polygon_delay_s;
        if (out_.hold(hold_s, true, seg.power_w, v_mps, seg.polyline, seg.vertex))
        {
          ++stats_.polygon_holds;
        }
      }
      out_.keep(seg);
    }
    if (sky_)
    {
      out_.skyMove(last.end_m, last.end_m + directionOf(last) * run_out_m, v_mps, last.polyline, last.vertex);
    }
    if (out_.hold(options_.mark_delay_s, false, 0.0, 0.0, last.polyline, last.vertex))
    {
      ++stats_.delay_holds;
    }
  }

  const std::vector<PathSegment>& segs_;
  const std::vector<Group> groups_;
  const NcProgramOptions& options_;
  NcProgramStats& stats_;
  const bool sky_;
  const double min_angle_rad_;
  ProgramWriter out_;
};
}  // namespace

NcProgramOptions NcProgramOptions::from(const NcConfig& nc, const Recipe& recipe)
{
  NcProgramOptions o;
  o.recipe = recipe;
  o.implicit_jump_speed_mps = nc.implicit_jump_speed_mps;
  o.mark_delay_s = nc.mark_delay_s;
  o.jump_delay_s = nc.jump_delay_s;
  o.polygon_delay_s = nc.polygon_delay_s;
  o.polygon_delay_by_angle = (nc.polygon_delay_mode == "angle");
  o.skywriting = nc.skywriting;
  return o;  // speed_cap_mps stays +inf: the caller sets it from the filter limits
}

NcProgram buildNcProgram(const Job& job, const NcProgramOptions& options)
{
  validateOptions(options);
  NcProgram program;
  Job recipe_job = applyRecipe(job, options.recipe);
  const double cap_mps = options.speed_cap_mps;
  for (Polyline& line : recipe_job.polylines)
  {
    if (!(line.dwell_s > 0.0) && line.speed_mps > cap_mps)
    {
      line.speed_mps = cap_mps;
      ++program.stats.capped_polylines;
    }
  }
  // The implicit jumps obey the cap too (they are moves of the same mirrors).
  const double implicit_mps = std::min(options.implicit_jump_speed_mps, cap_mps);
  NcProgramOptions effective = options;
  effective.implicit_jump_speed_mps = implicit_mps;

  const PathTimeline base(recipe_job, implicit_mps);
  ProgramBuilder builder(base.segments(), effective, program.stats);
  program.timeline = PathTimeline::fromSegments(builder.build());
  program.stats.added_time_s = program.timeline.duration() - base.duration();
  program.laser_on_delay_s = options.recipe.laser_on_delay_s;
  program.laser_off_delay_s = options.recipe.laser_off_delay_s;
  program.gate = LaserGate(program.timeline, program.laser_on_delay_s, program.laser_off_delay_s);
  return program;
}

NcProgram ncProgramFromSegments(std::vector<PathSegment> segments, double laser_on_delay_s, double laser_off_delay_s,
                                const NcProgramStats& stats)
{
  NcProgram program;
  program.timeline = PathTimeline::fromSegments(std::move(segments));
  program.laser_on_delay_s = laser_on_delay_s;
  program.laser_off_delay_s = laser_off_delay_s;
  program.gate = LaserGate(program.timeline, laser_on_delay_s, laser_off_delay_s);
  program.stats = stats;
  return program;
}
}  // namespace scanhead
