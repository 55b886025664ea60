/// \file test_nc_program.cpp
/// \brief The NC program (SPEC §2.5): timeline from segments, recipe and speed cap, mark, jump and
/// polygon delays, skywriting, and the laser gate on it.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "fixtures/polyline_fixture.hpp"
#include "scanhead/common/errors.hpp"
#include "scanhead/nc/nc_program.hpp"

using scanhead::ConfigError;
using scanhead::InputError;
using scanhead::Job;
using scanhead::NcProgram;
using scanhead::NcProgramOptions;
using scanhead::PathSegment;
using scanhead::PathTimeline;
using scanhead::PolylineRole;
using scanhead::PolylineType;

namespace
{
using scanhead::test_support::line;
using V = Eigen::Vector2d;
constexpr double kJumpSpeed = 4.5;

/// Mark with 3 corners, explicit jump, implicit jump, mark, implicit jump, dwell, contiguous
/// straight mark with a collinear vertex (see ProgramDurationIsSumOfMovesAndDelays).
Job delayJob()
{
  Job job;
  job.name = "delays";
  job.polylines.push_back(
      line(PolylineType::Mark, 1.2, 150.0, {{0, 0}, {2e-3, 0}, {2e-3, 1.5e-3}, {0.5e-3, 3e-3}, {0.5e-3, 3.7e-3}}));
  job.polylines.push_back(line(PolylineType::Jump, 5.0, 0.0, {{0.5e-3, 3.7e-3}, {5e-3, 5e-3}}));
  job.polylines.push_back(line(PolylineType::Mark, 0.9, 100.0, {{6e-3, 5e-3}, {7e-3, 5e-3}}));
  scanhead::Polyline spot = line(PolylineType::Mark, 0.0, 80.0, {{8e-3, 5e-3}});
  spot.dwell_s = 0.3e-3;
  job.polylines.push_back(spot);
  job.polylines.push_back(line(PolylineType::Mark, 0.7, 90.0, {{8e-3, 5e-3}, {8e-3, 6e-3}, {8e-3, 7e-3}}));
  return job;
}

/// Σ L/v + Σ dwell of a job on its own timeline, in long double from the polylines' points.
long double sumOfMoves(const Job& job, double implicit_speed)
{
  long double t = 0.0L;
  bool first = true;
  V prev(0, 0);
  for (const auto& p : job.polylines)
  {
    if (!first)
      t += static_cast<long double>((p.points.front() - prev).norm()) / implicit_speed;
    first = false;
    t += p.dwell_s;
    for (std::size_t v = 0; v + 1 < p.points.size(); ++v)
      t += static_cast<long double>((p.points[v + 1] - p.points[v]).norm()) / p.speed_mps;
    prev = p.points.back();
  }
  return t;
}

std::string configMessage(const Job& job, const NcProgramOptions& options)
{
  try
  {
    scanhead::buildNcProgram(job, options);
  }
  catch (const ConfigError& e)
  {
    return e.what();
  }
  return "";
}

NcProgramOptions plainOptions()
{
  NcProgramOptions o;
  o.implicit_jump_speed_mps = kJumpSpeed;
  return o;
}
}  // namespace

// The segments of a job's timeline give back bit-identical start times and duration (same prefix
// sums in the same order); input start times are ignored.
TEST(PathTimelineFromSegments, BitEqualToTheJobTimeline)
{
  const Job job = delayJob();
  const PathTimeline tl(job, kJumpSpeed);
  std::vector<PathSegment> segs = tl.segments();
  for (auto& s : segs)
    s.t_start_s = -1.0;  // recomputed
  const PathTimeline copy = PathTimeline::fromSegments(segs);
  ASSERT_EQ(copy.segments().size(), tl.segments().size());
  for (std::size_t k = 0; k < segs.size(); ++k)
  {
    EXPECT_EQ(copy.segments()[k].t_start_s, tl.segments()[k].t_start_s) << k;
    EXPECT_EQ(copy.segments()[k].duration_s, tl.segments()[k].duration_s) << k;
  }
  EXPECT_EQ(copy.duration(), tl.duration());
  EXPECT_TRUE(copy.hasPoints());
  EXPECT_EQ(copy.startPoint(), tl.startPoint());
  EXPECT_EQ(copy.endPoint(), tl.endPoint());
  PathTimeline::Cursor a;
  PathTimeline::Cursor b;
  for (double t = 0.0; t < tl.duration(); t += 1e-5)
  {
    ASSERT_EQ(copy.positionAt(t, a), tl.positionAt(t, b)) << t;
  }

  const PathTimeline empty = PathTimeline::fromSegments({});
  EXPECT_FALSE(empty.hasPoints());
  EXPECT_EQ(empty.duration(), 0.0);
}

// Durations must be finite and > 0; each segment starts where the previous one ended, within
// kSamePointTolerance_m (1e-12 m); points finite.
TEST(PathTimelineFromSegments, Errors)
{
  const PathTimeline tl(delayJob(), kJumpSpeed);
  for (const double bad : {0.0, -1e-6, std::nan(""), std::numeric_limits<double>::infinity()})
  {
    std::vector<PathSegment> segs = tl.segments();
    segs[3].duration_s = bad;
    EXPECT_THROW(PathTimeline::fromSegments(segs), InputError) << bad;
  }
  std::vector<PathSegment> segs = tl.segments();
  segs[2].start_m.x() += 0.5e-12;  // within tolerance
  EXPECT_NO_THROW(PathTimeline::fromSegments(segs));
  segs[2].start_m.x() += 2e-12;
  EXPECT_THROW(PathTimeline::fromSegments(segs), InputError);
  segs = tl.segments();
  segs[4].end_m.y() = std::nan("");
  EXPECT_THROW(PathTimeline::fromSegments(segs), InputError);
}

// Mark and jump delays, polygon delays (fixed), holds counted and placed:
//  polyline 0: 4 moves, corners 90°, 45°, 45°, mark delay;  polyline 1: explicit jump, jump delay;
//  implicit jump to polyline 2 (a jump right after a jump: its own jump delay), polyline 2, mark
//  delay; implicit jump + jump delay; the dwell (kept, no delay); polyline 4 contiguous to the
//  dwell, collinear vertex (no hold), mark delay.
// Duration = Σ L/v + dwell + 3·mark + 3·jump + 3·polygon delays, against a long double sum:
// tolerance 1e-15 relative (≈ 25 double roundings of 1.1e-16 on positive terms).
TEST(NcProgram, ProgramDurationIsSumOfMovesAndDelays)
{
  const Job job = delayJob();
  NcProgramOptions o = plainOptions();
  o.mark_delay_s = 100e-6;
  o.jump_delay_s = 250e-6;
  o.polygon_delay_s = 50e-6;
  const NcProgram prog = scanhead::buildNcProgram(job, o);
  const long double moves = sumOfMoves(job, kJumpSpeed);
  const long double expected = moves + 3 * 100e-6L + 3 * 250e-6L + 3 * 50e-6L;
  EXPECT_NEAR(prog.timeline.duration(), static_cast<double>(expected), 1e-15 * static_cast<double>(expected));
  EXPECT_EQ(prog.stats.delay_holds, 6u);
  EXPECT_EQ(prog.stats.polygon_holds, 3u);
  EXPECT_EQ(prog.stats.skywritten_corners, 0u);
  EXPECT_EQ(prog.stats.capped_polylines, 0u);
  EXPECT_NEAR(prog.stats.added_time_s, 3 * 100e-6 + 3 * 250e-6 + 3 * 50e-6, 1e-15 * prog.timeline.duration());

  // the sequence: M=move of a mark, P=polygon hold, D=mark delay, J=jump move, d=jump delay,
  // S=dwell
  const auto& segs = prog.timeline.segments();
  std::string kinds;
  for (std::size_t k = 0; k < segs.size(); ++k)
  {
    const PathSegment& s = segs[k];
    if (s.delay)
    {
      ASSERT_GT(k, 0u);
      EXPECT_FALSE(s.dwell);
      EXPECT_EQ(s.length_m, 0.0);
      EXPECT_EQ(s.start_m, s.end_m);
      kinds += s.mark ? 'P' : (segs[k - 1].mark ? 'D' : 'd');
    }
    else if (s.dwell)
      kinds += 'S';
    else
      kinds += s.mark ? 'M' : 'J';
  }
  EXPECT_EQ(kinds, "MPMPMPMDJdJdMDJdSMMD");
  // polygon holds: laser on at the polyline's power and speed, at the corner, fixed duration
  EXPECT_EQ(segs[1].start_m, V(2e-3, 0));
  EXPECT_EQ(segs[1].power_w, 150.0);
  EXPECT_EQ(segs[1].speed_mps, 1.2);
  EXPECT_EQ(segs[1].duration_s, 50e-6);
  // mark and jump holds: laser off, power 0
  EXPECT_EQ(segs[7].duration_s, 100e-6);
  EXPECT_EQ(segs[7].power_w, 0.0);
  EXPECT_EQ(segs[9].duration_s, 250e-6);
  EXPECT_TRUE(segs[10].implicit_jump);
  EXPECT_EQ(segs[11].duration_s, 250e-6);
  // laser bursts: polyline 0 with its polygon holds; polyline 2; dwell + polyline 4
  ASSERT_EQ(prog.gate.windows().size(), 3u);
  EXPECT_EQ(prog.gate.windows()[0].end_segment, 7u);
  EXPECT_EQ(prog.gate.windows()[2].first_segment, 16u);
  EXPECT_EQ(prog.gate.windows()[2].end_segment, 19u);

  // no delays: the program is the job's timeline, bit for bit
  const NcProgram plain = scanhead::buildNcProgram(job, plainOptions());
  const PathTimeline tl(job, kJumpSpeed);
  ASSERT_EQ(plain.timeline.segments().size(), tl.segments().size());
  EXPECT_EQ(plain.timeline.duration(), tl.duration());
  EXPECT_EQ(plain.stats.added_time_s, 0.0);
}

// Polygon delay by angle: hold = delay·gamma/180°: the 90° corner holds exactly half the delay,
// the 45° corners a quarter (1e-15 relative: gamma from atan2 of a rounded direction).
TEST(NcProgram, PolygonDelayByAngle)
{
  NcProgramOptions o = plainOptions();
  o.polygon_delay_s = 80e-6;
  o.polygon_delay_by_angle = true;
  const NcProgram prog = scanhead::buildNcProgram(delayJob(), o);
  EXPECT_EQ(prog.stats.polygon_holds, 3u);
  std::vector<double> holds;
  for (const PathSegment& s : prog.timeline.segments())
    if (s.delay)
      holds.push_back(s.duration_s);
  ASSERT_EQ(holds.size(), 3u);
  EXPECT_EQ(holds[0], 40e-6);
  EXPECT_NEAR(holds[1], 20e-6, 1e-15 * 20e-6);
  EXPECT_NEAR(holds[2], 20e-6, 1e-15 * 20e-6);
}

// Skywriting, v = 1 m/s: run-in 10 µm + 100 µs·v = 110 µm, run-out 5 µm + 50 µs·v = 55 µm,
// min angle 30°. Mark (0,0)→(2,0)→(2,2)→(2.2,3) mm: the 90° corner is skywritten, the 11.3° corner
// is not (polygon hold there). Positions are exact sums and products of the same doubles the
// builder uses: tolerance 1e-18 m (coordinates ~1e-3 m round at ~2e-19 m).
TEST(NcProgram, SkywritingGeometry)
{
  Job job;
  job.polylines.push_back(line(PolylineType::Jump, 5.0, 0.0, {{-1e-3, -1e-3}, {0, 0}}));
  job.polylines.push_back(line(PolylineType::Mark, 1.0, 200.0, {{0, 0}, {2e-3, 0}, {2e-3, 2e-3}, {2.2e-3, 3e-3}}));
  job.polylines.push_back(line(PolylineType::Jump, 5.0, 0.0, {{2.2e-3, 3e-3}, {-1e-3, -1e-3}}));
  NcProgramOptions o = plainOptions();
  o.polygon_delay_s = 20e-6;
  o.recipe.laser_on_delay_s = 10e-6;
  o.recipe.laser_off_delay_s = 10e-6;
  o.skywriting.enabled = true;
  o.skywriting.run_in_m = 10e-6;
  o.skywriting.run_in_s = 100e-6;
  o.skywriting.run_out_m = 5e-6;
  o.skywriting.run_out_s = 50e-6;
  o.skywriting.min_angle_deg = 30.0;
  const NcProgram prog = scanhead::buildNcProgram(job, o);
  const double lin = 10e-6 + 100e-6 * 1.0;
  const double lout = 5e-6 + 50e-6 * 1.0;
  const auto& s = prog.timeline.segments();
  ASSERT_EQ(s.size(), 11u);
  EXPECT_EQ(prog.stats.skywritten_corners, 1u);
  EXPECT_EQ(prog.stats.polygon_holds, 1u);
  const auto near = [](const V& a, const V& b) { return (a - b).norm() < 1e-18; };
  // 0: the jump now ends at the run-in start; 1: run-in to the first point
  EXPECT_TRUE(near(s[0].end_m, V(-lin, 0)));
  EXPECT_TRUE(near(s[1].start_m, V(-lin, 0)));
  EXPECT_EQ(s[1].end_m, V(0, 0));
  // 3: run-out = corner + d_in·L_out; 4: turn to corner − d_out·L_in; 5: run-in back to the corner
  const V corner(2e-3, 0);
  EXPECT_EQ(s[3].start_m, corner);
  EXPECT_TRUE(near(s[3].end_m, corner + V(1, 0) * lout));
  EXPECT_TRUE(near(s[4].end_m, corner - V(0, 1) * lin));
  EXPECT_EQ(s[5].end_m, corner);
  EXPECT_NEAR(s[4].length_m, std::hypot(lin, lout), 1e-18);
  for (const int k : {1, 3, 4, 5, 9})
  {
    EXPECT_TRUE(s[k].skywriting) << k;
    EXPECT_FALSE(s[k].mark) << k;
    EXPECT_EQ(s[k].power_w, 0.0) << k;
    EXPECT_EQ(s[k].speed_mps, 1.0) << k;
  }
  // the shallow corner: untouched moves (bit-equal to the job's), a polygon hold, laser on
  const PathTimeline base(job, kJumpSpeed);
  EXPECT_TRUE(s[7].delay && s[7].mark);
  EXPECT_EQ(s[7].start_m, V(2e-3, 2e-3));
  EXPECT_EQ(s[6].duration_s, base.segments()[2].duration_s);
  EXPECT_EQ(s[8].start_m, base.segments()[3].start_m);
  EXPECT_EQ(s[8].end_m, base.segments()[3].end_m);
  EXPECT_EQ(s[8].duration_s, base.segments()[3].duration_s);
  // 9: run-out after the last point along the last direction; 10: the jump starts there
  const V d_last = V(0.2e-3, 1e-3).normalized();
  EXPECT_TRUE(near(s[9].end_m, V(2.2e-3, 3e-3) + d_last * lout));
  EXPECT_EQ(s[10].start_m, s[9].end_m);
  EXPECT_EQ(s[10].end_m, V(-1e-3, -1e-3));
  // total skywriting length: 2 run-ins, 2 run-outs, the turn (1e-18 m: 5 terms ~1e-4 m)
  double sky_m = 0.0;
  for (const auto& seg : s)
    if (seg.skywriting)
      sky_m += seg.length_m;
  EXPECT_NEAR(sky_m, 2 * lin + 2 * lout + std::hypot(lin, lout), 1e-18);
  // duration: the moves as built + the hold (1e-15 relative, long double reference)
  long double expected = 20e-6L;
  for (const auto& seg : s)
    if (!seg.delay)
      expected += static_cast<long double>((seg.end_m - seg.start_m).norm()) / seg.speed_mps;
  EXPECT_NEAR(prog.timeline.duration(), static_cast<double>(expected), 1e-15 * static_cast<double>(expected));
  // two laser bursts: the mark is split at the skywritten corner
  ASSERT_EQ(prog.gate.windows().size(), 2u);
  EXPECT_EQ(prog.gate.windows()[0].first_segment, 2u);
  EXPECT_EQ(prog.gate.windows()[0].end_segment, 3u);
  EXPECT_EQ(prog.gate.windows()[1].first_segment, 6u);
  EXPECT_EQ(prog.gate.windows()[1].end_segment, 9u);
  EXPECT_EQ(prog.gate.windows()[1].on_s, s[6].t_start_s + 10e-6);

  // min angle 95°: no corner skywritten, only the run-in and run-out at the ends
  o.skywriting.min_angle_deg = 95.0;
  const NcProgram none = scanhead::buildNcProgram(job, o);
  EXPECT_EQ(none.stats.skywritten_corners, 0u);
  EXPECT_EQ(none.stats.polygon_holds, 2u);
  EXPECT_EQ(none.gate.windows().size(), 1u);
}

// Two contiguous marks (no jump between) with skywriting: the first one's run-out and the second
// one's run-in start are linked by a laser-off skywriting move at the second mark's speed, after
// the mark delay.
TEST(NcProgram, SkywritingLinksContiguousMarks)
{
  Job job;
  job.polylines.push_back(line(PolylineType::Mark, 1.0, 200.0, {{0, 0}, {1e-3, 0}}));
  job.polylines.push_back(line(PolylineType::Mark, 2.0, 100.0, {{1e-3, 0}, {1e-3, 1e-3}}));
  NcProgramOptions o = plainOptions();
  o.mark_delay_s = 30e-6;
  o.skywriting.enabled = true;
  o.skywriting.run_in_s = 100e-6;
  o.skywriting.run_out_s = 50e-6;
  const NcProgram prog = scanhead::buildNcProgram(job, o);
  const auto& s = prog.timeline.segments();
  // run-in, mark, run-out, mark delay, link, run-in, mark, run-out, mark delay
  ASSERT_EQ(s.size(), 9u);
  EXPECT_TRUE(s[3].delay);
  EXPECT_TRUE(s[4].skywriting);
  EXPECT_FALSE(s[4].mark);
  EXPECT_EQ(s[4].speed_mps, 2.0);
  EXPECT_EQ(s[4].start_m, V(1e-3 + 50e-6, 0));
  EXPECT_NEAR((s[4].end_m - V(1e-3, -200e-6)).norm(), 0.0, 1e-18);  // run-in 100 µs at 2 m/s
  EXPECT_EQ(s[6].start_m, V(1e-3, 0));
  EXPECT_EQ(prog.stats.delay_holds, 2u);
  EXPECT_EQ(prog.gate.windows().size(), 2u);
}

// THESIS recipe 1 on a contour/jump/contour/jump/hatch job, speed cap 1.2 m/s: contours 1.5 →
// 1.2, jumps 4.5 and 6 → 1.2, hatch 1.0 kept, implicit jump 4.5 → 1.2; the gate switches on
// 395 µs after the first mark starts. Exact: copies and min().
TEST(NcProgram, RecipeAndSpeedCap)
{
  Job job;
  auto contour = [](std::vector<V> pts) {
    scanhead::Polyline p = line(PolylineType::Mark, 0.5, 10.0, std::move(pts));
    p.role = PolylineRole::Contour;
    return p;
  };
  job.polylines.push_back(contour({{0, 0}, {1e-3, 0}}));
  job.polylines.push_back(line(PolylineType::Jump, 1.0, 0.0, {{1e-3, 0}, {1e-3, 1e-3}}));
  job.polylines.push_back(contour({{1e-3, 1e-3}, {0, 1e-3}}));
  job.polylines.push_back(line(PolylineType::Jump, 1.0, 0.0, {{0, 1e-3}, {0, 2e-3}}));
  scanhead::Polyline hatch = line(PolylineType::Mark, 0.5, 10.0, {{0, 2e-3}, {1e-3, 2e-3}});
  hatch.role = PolylineRole::Hatch;
  job.polylines.push_back(hatch);
  job.polylines.push_back(contour({{0, 3e-3}, {1e-3, 3e-3}}));  // implicit jump before it

  scanhead::RecipeConfig rc;
  rc.preset = "thesis1";
  NcProgramOptions o = plainOptions();
  o.recipe = scanhead::resolveRecipe(rc);
  const NcProgram uncapped = scanhead::buildNcProgram(job, o);
  const auto& u = uncapped.timeline.segments();
  ASSERT_EQ(u.size(), 7u);
  const double expected_uncapped[] = {1.5, 4.5, 1.5, 6.0, 1.0, 4.5, 1.5};
  for (std::size_t k = 0; k < u.size(); ++k)
    EXPECT_EQ(u[k].speed_mps, expected_uncapped[k]) << k;
  EXPECT_EQ(u[0].power_w, 200.0);
  EXPECT_EQ(uncapped.gate.windows()[0].on_s, 395e-6);
  EXPECT_EQ(uncapped.gate.windows()[0].off_s, u[0].duration_s + 107e-6);

  o.speed_cap_mps = 1.2;
  const NcProgram capped = scanhead::buildNcProgram(job, o);
  const auto& c = capped.timeline.segments();
  ASSERT_EQ(c.size(), 7u);
  const double expected_capped[] = {1.2, 1.2, 1.2, 1.2, 1.0, 1.2, 1.2};
  for (std::size_t k = 0; k < c.size(); ++k)
    EXPECT_EQ(c[k].speed_mps, expected_capped[k]) << k;
  EXPECT_TRUE(c[5].implicit_jump);
  EXPECT_EQ(capped.stats.capped_polylines, 5u);  // 3 contours, 2 jumps (the implicit one is no polyline)
  EXPECT_EQ(capped.stats.added_time_s, 0.0);     // the cap changes Σ L/v itself, adds no delay
}

// Bad options: ConfigError naming the field and the value; NcProgramOptions::from maps NcConfig.
TEST(NcProgram, OptionsValidationAndMapping)
{
  const Job job = delayJob();
  NcProgramOptions o = plainOptions();
  o.mark_delay_s = -1e-6;
  EXPECT_EQ(configMessage(job, o), "nc.mark_delay_s must be >= 0 (got -1e-06)");
  o = plainOptions();
  o.polygon_delay_s = std::nan("");
  EXPECT_EQ(configMessage(job, o), "nc.polygon_delay_s must be >= 0 (got nan)");
  o = plainOptions();
  o.speed_cap_mps = 0.0;
  EXPECT_EQ(configMessage(job, o), "nc_program.speed_cap_mps must be > 0 (got 0)");
  o = plainOptions();
  o.skywriting.enabled = true;
  o.skywriting.min_angle_deg = 200.0;
  EXPECT_EQ(configMessage(job, o), "nc.skywriting.min_angle_deg must be in [0, 180) (got 200)");
  o.skywriting.min_angle_deg = 30.0;
  o.skywriting.run_out_s = -1e-4;
  EXPECT_EQ(configMessage(job, o), "nc.skywriting.run_out_s must be >= 0 (got -0.0001)");
  o = plainOptions();
  o.recipe.laser_on_delay_s = std::numeric_limits<double>::infinity();
  EXPECT_EQ(configMessage(job, o), "recipe.laser_on_delay_s must be finite (got inf)");
  o = plainOptions();
  o.implicit_jump_speed_mps = 0.0;  // the job needs implicit jumps: PathTimeline's ConfigError
  EXPECT_THROW(scanhead::buildNcProgram(job, o), ConfigError);

  scanhead::NcConfig nc;
  nc.implicit_jump_speed_mps = 3.3;
  nc.mark_delay_s = 1e-5;
  nc.jump_delay_s = 2e-5;
  nc.polygon_delay_s = 3e-5;
  nc.polygon_delay_mode = "angle";
  nc.skywriting.enabled = true;
  nc.skywriting.run_in_m = 7e-6;
  scanhead::Recipe r;
  r.laser_on_delay_s = 1.25e-4;
  const NcProgramOptions m = NcProgramOptions::from(nc, r);
  EXPECT_EQ(m.implicit_jump_speed_mps, 3.3);
  EXPECT_EQ(m.mark_delay_s, 1e-5);
  EXPECT_EQ(m.jump_delay_s, 2e-5);
  EXPECT_EQ(m.polygon_delay_s, 3e-5);
  EXPECT_TRUE(m.polygon_delay_by_angle);
  EXPECT_TRUE(m.skywriting.enabled);
  EXPECT_EQ(m.skywriting.run_in_m, 7e-6);
  EXPECT_EQ(m.recipe.laser_on_delay_s, 1.25e-4);
  EXPECT_TRUE(std::isinf(m.speed_cap_mps));
  nc.polygon_delay_mode = "fixed";
  EXPECT_FALSE(NcProgramOptions::from(nc, r).polygon_delay_by_angle);
}
