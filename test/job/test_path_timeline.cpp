/// \file test_path_timeline.cpp
/// \brief The exact timeline of a job (SPEC §2.1) and the corners timed on it.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "fixtures/polyline_fixture.hpp"
#include "scanhead/common/errors.hpp"
#include "scanhead/job/path_timeline.hpp"
#include "scanhead/job/scan_job.hpp"

using scanhead::Job;
using scanhead::PathTimeline;
using scanhead::Polyline;
using scanhead::PolylineType;

namespace
{
using scanhead::test_support::line;

/// Mark (0,0)→(1.234567 mm, 0)→(1.234567, 0.98765) at 0.7 m/s (with a repeated point), an
/// implicit jump, a mark at 1.3 m/s, an explicit jump polyline, a contiguous mark at 2.1 m/s.
Job mixedJob()
{
  Job job;
  job.name = "mixed";
  job.polylines.push_back(line(PolylineType::Mark, 0.7, 150.0,
                               {{0.0, 0.0}, {1.234567e-3, 0.0}, {1.234567e-3, 0.0}, {1.234567e-3, 0.98765e-3}}));
  job.polylines.push_back(line(PolylineType::Mark, 1.3, 90.0, {{3e-3, 1e-3}, {5.5e-3, 2.2e-3}}));
  job.polylines.push_back(line(PolylineType::Jump, 6.0, 0.0, {{5.5e-3, 2.2e-3}, {-4e-3, -7e-3}}));
  job.polylines.push_back(line(PolylineType::Mark, 2.1, 200.0, {{-4e-3, -7e-3}, {-3.1e-3, -6.95e-3}, {-3e-3, -5e-3}}));
  return job;
}
constexpr double kJumpSpeed = 4.5;
}  // namespace

// Total duration = Σ L/v over every move, implicit jump included, against an independent sum in
// long double. Tolerance 1e-15 relative: 7 terms in double, each rounding ≤ 1.1e-16 relative.
TEST(PathTimeline, TotalDurationIsSumOfLengthOverSpeed)
{
  const Job job = mixedJob();
  const PathTimeline tl(job, kJumpSpeed);
  long double expected = 0.0L;
  Eigen::Vector2d prev = job.polylines[0].points[0];
  int moves = 0;
  for (const Polyline& p : job.polylines)
  {
    const long double jump = (p.points[0] - prev).norm();
    if (jump > 0)
    {
      expected += jump / kJumpSpeed;
      ++moves;
    }
    for (std::size_t v = 0; v + 1 < p.points.size(); ++v)
    {
      const long double len = (p.points[v + 1] - p.points[v]).norm();
      if (len > 0)
      {
        expected += len / p.speed_mps;
        ++moves;
      }
    }
    prev = p.points.back();
  }
  ASSERT_EQ(static_cast<int>(tl.segments().size()), moves);  // zero-length edge skipped
  EXPECT_EQ(moves, 7);
  EXPECT_NEAR(tl.duration(), static_cast<double>(expected), 1e-15 * static_cast<double>(expected));
  // t_start are the prefix sums, gapless
  double t = 0.0;
  for (const auto& s : tl.segments())
  {
    EXPECT_EQ(s.t_start_s, t);
    EXPECT_DOUBLE_EQ(s.duration_s, s.length_m / s.speed_mps);
    t += s.duration_s;
  }
  EXPECT_EQ(t, tl.duration());
  // the implicit jump: segment 2, from the end of polyline 0 to the start of polyline 1
  const auto& jump = tl.segments()[2];
  EXPECT_TRUE(jump.implicit_jump);
  EXPECT_FALSE(jump.mark);
  EXPECT_EQ(jump.speed_mps, kJumpSpeed);
  EXPECT_EQ(jump.polyline, 1u);
  EXPECT_EQ(jump.power_w, 0.0);
  // explicit jump polyline: not a mark, power 0, its own speed; no jump inserted before polyline 3
  EXPECT_FALSE(tl.segments()[4].mark);
  EXPECT_FALSE(tl.segments()[4].implicit_jump);
  EXPECT_EQ(tl.segments()[4].speed_mps, 6.0);
  EXPECT_EQ(tl.segments()[5].polyline, 3u);
  EXPECT_TRUE(tl.segments()[5].mark);
}

// A sample just after a corner lies on the second segment at distance v2·(t_n − t_corner) from
// the corner: the remainder carries across the segment end. Two contiguous polylines at
// different speeds so the carried time matters. Tolerance 1e-15 m: coordinates ~1e-3 m round at
// ~1e-19 m, times at ~1e-19 s.
TEST(PathTimeline, SampleAfterCornerCarriesTheRemainder)
{
  const double ts = 1e-5;
  const double v1 = 0.7;
  const double v2 = 1.3;
  const Eigen::Vector2d a(0.0, 0.0);
  const Eigen::Vector2d corner(1.234567e-3, 0.0);
  const Eigen::Vector2d b(1.234567e-3 + 0.6e-3, 0.8e-3);  // 1 mm leg, direction (0.6, 0.8)
  Job job;
  job.polylines.push_back(line(PolylineType::Mark, v1, 100.0, {a, corner}));
  job.polylines.push_back(line(PolylineType::Mark, v2, 100.0, {corner, b}));
  const PathTimeline tl(job, kJumpSpeed);
  ASSERT_EQ(tl.segments().size(), 2u);  // contiguous: no jump
  const double t_corner = corner.norm() / v1;
  EXPECT_EQ(tl.segments()[1].t_start_s, t_corner);
  const std::size_t n_after = static_cast<std::size_t>(std::ceil(t_corner / ts));
  const double t_n = static_cast<double>(n_after) * ts;
  ASSERT_GT(t_n, t_corner);
  ASSERT_LT(t_n - t_corner, ts);
  PathTimeline::Cursor cursor;
  const Eigen::Vector2d before = tl.positionAt(t_n - ts, cursor);
  const Eigen::Vector2d p = tl.positionAt(t_n, cursor);
  const Eigen::Vector2d dir(0.6, 0.8);
  const Eigen::Vector2d expected = corner + v2 * (t_n - t_corner) * dir;
  EXPECT_NEAR(p.x(), expected.x(), 1e-15);
  EXPECT_NEAR(p.y(), expected.y(), 1e-15);
  // the sample before lies on the first segment at v1·t
  EXPECT_NEAR(before.x(), v1 * (t_n - ts), 1e-15);
  EXPECT_EQ(before.y(), 0.0);
  // the segment containing t_n is the second
  EXPECT_EQ(tl.segmentAt(t_n, cursor), 1u);
  EXPECT_EQ(tl.segmentAt(t_corner, cursor), 1u);  // half-open: the corner time starts the next
}

TEST(PathTimeline, HoldsEndsAndGatesPowerHalfOpen)
{
  const Job job = mixedJob();
  const PathTimeline tl(job, kJumpSpeed);
  PathTimeline::Cursor c;
  EXPECT_EQ(tl.positionAt(-1.0, c), Eigen::Vector2d(0.0, 0.0));
  EXPECT_EQ(tl.positionAt(0.0, c), Eigen::Vector2d(0.0, 0.0));
  EXPECT_EQ(tl.positionAt(tl.duration(), c), Eigen::Vector2d(-3e-3, -5e-3));
  EXPECT_EQ(tl.positionAt(tl.duration() + 1.0, c), Eigen::Vector2d(-3e-3, -5e-3));
  PathTimeline::Cursor lc;
  EXPECT_EQ(tl.powerAt(-1e-9, lc), 0.0);
  EXPECT_EQ(tl.powerAt(0.0, lc), 150.0);
  const auto& jump = tl.segments()[2];
  EXPECT_EQ(tl.powerAt(std::nextafter(jump.t_start_s, 0.0), lc), 150.0);
  EXPECT_EQ(tl.powerAt(jump.t_start_s, lc), 0.0);
  EXPECT_EQ(tl.powerAt(tl.segments()[3].t_start_s, lc), 90.0);
  EXPECT_EQ(tl.powerAt(tl.segments()[4].t_start_s + 1e-7, lc), 0.0);  // explicit jump
  EXPECT_EQ(tl.powerAt(std::nextafter(tl.duration(), 0.0), lc), 200.0);
  EXPECT_EQ(tl.powerAt(tl.duration(), lc), 0.0);
  // a reader going backwards still gets the right segment
  EXPECT_EQ(tl.powerAt(1e-6, lc), 150.0);
}

TEST(PathTimeline, RejectsBadSpeeds)
{
  Job job;
  job.name = "bad";
  job.polylines.push_back(line(PolylineType::Mark, 0.0, 1.0, {{0, 0}, {1e-3, 0}}));
  EXPECT_THROW(PathTimeline(job, kJumpSpeed), scanhead::InputError);
  job.polylines[0].speed_mps = 1.0;
  job.polylines.push_back(line(PolylineType::Mark, 1.0, 1.0, {{2e-3, 0}, {3e-3, 0}}));
  EXPECT_THROW(PathTimeline(job, 0.0), scanhead::ConfigError);  // a jump is needed
  EXPECT_NO_THROW(PathTimeline(Job(), 0.0));                    // empty job: nothing to time
}

// Corners inside MARK polylines, timed on the same timeline (the implicit jump counts),
// windows = half the adjacent durations, angle = direction change.
TEST(FindCorners, TimesAnglesAndWindows)
{
  Job job = mixedJob();
  const PathTimeline tl(job, kJumpSpeed);
  const auto corners = scanhead::findCorners(job, 1e-3, kJumpSpeed);
  // polyline 0: one 90° corner at vertex 2 (repeated point); polyline 3: one corner at vertex 1
  ASSERT_EQ(corners.size(), 2u);
  EXPECT_EQ(corners[0].polyline, 0u);
  EXPECT_EQ(corners[0].vertex, 2u);
  EXPECT_NEAR(corners[0].angle_rad, M_PI / 2, 1e-12);
  EXPECT_EQ(corners[0].time_s, 1.234567e-3 / 0.7);
  EXPECT_EQ(corners[0].window_in_s, 0.5 * 1.234567e-3 / 0.7);
  EXPECT_NEAR(corners[0].window_out_s, 0.5 * 0.98765e-3 / 0.7, 1e-18);
  EXPECT_EQ(corners[0].speed_mps, 0.7);
  EXPECT_EQ(corners[1].polyline, 3u);
  EXPECT_EQ(corners[1].vertex, 1u);
  EXPECT_EQ(corners[1].point, Eigen::Vector2d(-3.1e-3, -6.95e-3));
  EXPECT_EQ(corners[1].time_s, tl.segments()[6].t_start_s);  // after the implicit and explicit jumps
  const Eigen::Vector2d d_in = Eigen::Vector2d(0.9e-3, 0.05e-3).normalized();
  const Eigen::Vector2d d_out = Eigen::Vector2d(0.1e-3, 1.95e-3).normalized();
  EXPECT_NEAR(corners[1].angle_rad, std::acos(d_in.dot(d_out)), 1e-12);
  EXPECT_EQ(corners[1].window_in_s, 0.5 * tl.segments()[5].duration_s);
  EXPECT_EQ(corners[1].window_out_s, 0.5 * tl.segments()[6].duration_s);
  // a minimum angle above both: none; straight-on vertices never count
  EXPECT_TRUE(scanhead::findCorners(job, 1.6, kJumpSpeed).empty());
  Job straight;
  straight.polylines.push_back(line(PolylineType::Mark, 1.0, 1.0, {{0, 0}, {1e-3, 1e-3}, {2e-3, 2e-3}}));
  EXPECT_TRUE(scanhead::findCorners(straight, 0.0, kJumpSpeed).empty());
}

// A dwell (a spot): one segment of zero length lasting dwell_s at its point, with the polyline's
// power; implicit jumps lead to it and away as for any polyline. Sampled at 100 kHz, the laser
// is on at 100 W for 1 ms ± 1 sample (the sample grid against the two ends) and every sample in
// the dwell is exactly at the point; the duration is Σ L/v + the dwell.
TEST(PathTimeline, DwellIsASpotOfItsDuration)
{
  const Eigen::Vector2d spot(1e-3, 0.5e-3);
  Job job;
  job.name = "dwell";
  job.polylines.push_back(line(PolylineType::Mark, 1.0, 200.0, {{0.0, 0.0}, {0.7e-3, 0.0}}));
  Polyline dwell = line(PolylineType::Mark, 0.0, 100.0, {spot});  // speed unused by a dwell
  dwell.dwell_s = 1e-3;
  job.polylines.push_back(dwell);
  job.polylines.push_back(line(PolylineType::Mark, 2.0, 200.0, {spot, {2e-3, 0.5e-3}}));
  const PathTimeline tl(job, kJumpSpeed);
  ASSERT_EQ(tl.segments().size(), 4u);  // mark, implicit jump, dwell, mark (contiguous)
  EXPECT_TRUE(tl.segments()[1].implicit_jump);
  const auto& d = tl.segments()[2];
  EXPECT_TRUE(d.dwell);
  EXPECT_TRUE(d.mark);
  EXPECT_EQ(d.start_m, spot);
  EXPECT_EQ(d.end_m, spot);
  EXPECT_EQ(d.length_m, 0.0);
  EXPECT_EQ(d.duration_s, 1e-3);
  EXPECT_EQ(d.power_w, 100.0);
  EXPECT_EQ(d.polyline, 1u);
  const double jump = Eigen::Vector2d(0.3e-3, 0.5e-3).norm() / kJumpSpeed;
  // duration: 4 terms rounded in double, 1e-18 s (≈ 4 × 1.1e-16 × 2.4e-3 s)
  EXPECT_NEAR(tl.duration(), 0.7e-3 / 1.0 + jump + 1e-3 + 1e-3 / 2.0, 1e-18);
  EXPECT_EQ(tl.segments()[3].t_start_s, d.t_start_s + 1e-3);

  const double ts = 1e-5;
  PathTimeline::Cursor pc;
  PathTimeline::Cursor lc;
  int on_100 = 0;
  int in_dwell = 0;
  for (int n = 0; static_cast<double>(n) * ts < tl.duration() + 1e-4; ++n)
  {
    const double t = static_cast<double>(n) * ts;
    const double p = tl.powerAt(t, lc);
    if (p == 100.0)
      ++on_100;
    if (t >= d.t_start_s && t < d.t_start_s + d.duration_s)
    {
      ++in_dwell;
      EXPECT_EQ(tl.positionAt(t, pc), spot) << "t = " << t;
      EXPECT_EQ(p, 100.0);
    }
  }
  EXPECT_NEAR(on_100, 100, 1);
  EXPECT_EQ(on_100, in_dwell);
  // no corner at a dwell (zero length: no direction), none in these straight marks
  EXPECT_TRUE(scanhead::findCorners(job, 0.0, kJumpSpeed).empty());

  // a dwell on a JUMP polyline waits with the laser off
  job.polylines[1].type = PolylineType::Jump;
  const PathTimeline off(job, kJumpSpeed);
  PathTimeline::Cursor oc;
  EXPECT_EQ(off.powerAt(off.segments()[2].t_start_s + 0.5e-3, oc), 0.0);
  EXPECT_EQ(off.duration(), tl.duration());
}

TEST(PathTimeline, RejectsBadDwells)
{
  Job job;
  job.name = "bad dwell";
  job.polylines.push_back(line(PolylineType::Mark, 1.0, 1.0, {{0, 0}}));
  for (const double bad : {-1e-3, std::nan(""), std::numeric_limits<double>::infinity()})
  {
    job.polylines[0].dwell_s = bad;
    EXPECT_THROW(PathTimeline(job, kJumpSpeed), scanhead::InputError) << bad;
  }
  job.polylines[0].dwell_s = 1e-3;
  EXPECT_NO_THROW(PathTimeline(job, kJumpSpeed));
  job.polylines[0].points.push_back({1e-3, 0});  // a dwell has exactly one point
  EXPECT_THROW(PathTimeline(job, kJumpSpeed), scanhead::InputError);
}
