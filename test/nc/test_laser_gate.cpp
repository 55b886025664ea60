/// \file test_laser_gate.cpp
/// \brief The laser command with laser-on and laser-off delays on the command timeline (SPEC §2.5).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "fixtures/polyline_fixture.hpp"
#include "scanhead/common/errors.hpp"
#include "scanhead/job/path_timeline.hpp"
#include "scanhead/nc/laser_gate.hpp"

using scanhead::Job;
using scanhead::LaserGate;
using scanhead::LaserWindow;
using scanhead::PathTimeline;
using scanhead::PolylineType;

namespace
{
using scanhead::test_support::line;
constexpr double kJumpSpeed = 4.5;
constexpr double kInf = std::numeric_limits<double>::infinity();

double before(double t)
{
  return std::nextafter(t, -kInf);
}

/// jump (0,0)→(1.234567 mm, 0) at 6 m/s, mark 2.5 mm at 1.5 m/s and 200 W, jump back at 6 m/s.
Job jumpMarkJump()
{
  Job job;
  job.polylines.push_back(line(PolylineType::Jump, 6.0, 0.0, {{0, 0}, {1.234567e-3, 0}}));
  job.polylines.push_back(line(PolylineType::Mark, 1.5, 200.0, {{1.234567e-3, 0}, {3.734567e-3, 0}}));
  job.polylines.push_back(line(PolylineType::Jump, 6.0, 0.0, {{3.734567e-3, 0}, {0, 0}}));
  return job;
}

/// mark A (100 W, 1 m/s, 0.5 mm), jump of \p jump_m at 5 m/s, mark B (200 W, 2 m/s, 0.6 mm) with a
/// contiguous mark C (150 W, 0.8 m/s, 0.3 mm) after it.
Job twoBursts(double jump_m)
{
  Job job;
  job.polylines.push_back(line(PolylineType::Mark, 1.0, 100.0, {{0, 0}, {0.5e-3, 0}}));
  job.polylines.push_back(line(PolylineType::Jump, 5.0, 0.0, {{0.5e-3, 0}, {0.5e-3 + jump_m, 0}}));
  job.polylines.push_back(line(PolylineType::Mark, 2.0, 200.0, {{0.5e-3 + jump_m, 0}, {1.1e-3 + jump_m, 0}}));
  job.polylines.push_back(line(PolylineType::Mark, 0.8, 150.0, {{1.1e-3 + jump_m, 0}, {1.1e-3 + jump_m, 0.3e-3}}));
  return job;
}

/// Independent evaluation: linear scans over the windows and the timeline's segments.
double bruteForcePower(const LaserGate& gate, const PathTimeline& tl, double on_delay_s, double t, bool speed)
{
  for (const LaserWindow& w : gate.windows())
  {
    if (t >= w.on_s && t < w.off_s)
    {
      double tau = t - on_delay_s;
      tau = std::min(std::max(tau, w.burst_start_s), w.burst_end_s);
      double value = 0.0;
      for (std::size_t k = w.first_segment; k < w.end_segment; ++k)
      {
        const auto& s = tl.segments()[k];
        if (s.mark && s.t_start_s <= tau)
          value = speed ? s.speed_mps : s.power_w;
      }
      return value;
    }
  }
  return 0.0;
}
}  // namespace

// jump→mark→jump: on at mark start + on delay, off at mark end + off delay, in command time and
// not rounded to any sample grid (395 µs and 107 µs are kept to the last bit: EXPECT_EQ on the
// sums, which is what the constructor must compute).
TEST(LaserGate, OnAndOffInstantsOfOneMark)
{
  const PathTimeline tl(jumpMarkJump(), kJumpSpeed);
  ASSERT_EQ(tl.segments().size(), 3u);
  const double bs = tl.segments()[1].t_start_s;
  const double be = tl.segmentEnd(1);
  const LaserGate gate(tl, 395e-6, 107e-6);
  ASSERT_EQ(gate.windows().size(), 1u);
  const LaserWindow& w = gate.windows()[0];
  EXPECT_EQ(w.burst_start_s, bs);
  EXPECT_EQ(w.burst_end_s, be);
  EXPECT_EQ(w.on_s, bs + 395e-6);
  EXPECT_EQ(w.off_s, be + 107e-6);
  EXPECT_EQ(w.first_segment, 1u);
  EXPECT_EQ(w.end_segment, 2u);
  // bs = 1.234567 mm / 6 m/s = 205.76 µs: the on instant 600.76 µs is between samples
  EXPECT_NEAR(w.on_s, 1.234567e-3 / 6.0 + 395e-6, 1e-18);
  EXPECT_NE(std::fmod(w.on_s, 1e-5), 0.0);
  LaserGate::Cursor c;
  EXPECT_EQ(gate.powerAt(0.0, c), 0.0);
  EXPECT_EQ(gate.powerAt(before(w.on_s), c), 0.0);
  EXPECT_EQ(gate.powerAt(w.on_s, c), 200.0);
  EXPECT_EQ(gate.powerAt(be, c), 200.0);  // the NC stopped, the laser is still on
  EXPECT_EQ(gate.powerAt(before(w.off_s), c), 200.0);
  EXPECT_EQ(gate.powerAt(w.off_s, c), 0.0);  // half-open
  EXPECT_EQ(gate.powerAt(tl.duration() + 1.0, c), 0.0);
  EXPECT_EQ(gate.speedAt(w.on_s, c), 1.5);
  EXPECT_EQ(gate.speedAt(w.off_s, c), 0.0);
  // sampled at 100 kHz: lit samples = those in [on, off) (no rounding of the window to the grid)
  int lit = 0;
  int expected = 0;
  for (int n = 0; n < 200; ++n)
  {
    const double t = n * 1e-5;
    lit += gate.powerAt(t, c) > 0.0 ? 1 : 0;
    expected += (t >= bs + 395e-6 && t < be + 107e-6) ? 1 : 0;
  }
  EXPECT_EQ(lit, expected);
  EXPECT_EQ(expected, 137);  // [600.76 µs, 1979.43 µs): samples 61..197
}

// A negative on delay lights the laser before the NC starts the mark, with the burst's first power.
TEST(LaserGate, NegativeOnDelay)
{
  const PathTimeline tl(jumpMarkJump(), kJumpSpeed);
  const double bs = tl.segments()[1].t_start_s;
  const LaserGate gate(tl, -50e-6, 20e-6);
  ASSERT_EQ(gate.windows().size(), 1u);
  EXPECT_EQ(gate.windows()[0].on_s, bs - 50e-6);
  LaserGate::Cursor c;
  EXPECT_EQ(gate.powerAt(before(bs - 50e-6), c), 0.0);
  EXPECT_EQ(gate.powerAt(bs - 50e-6, c), 200.0);
  EXPECT_EQ(gate.powerAt(bs - 1e-6, c), 200.0);  // during the jump, NC time
  EXPECT_EQ(gate.powerAt(tl.segmentEnd(1) + 19e-6, c), 200.0);
  EXPECT_EQ(gate.powerAt(tl.segmentEnd(1) + 20e-6, c), 0.0);
}

// Off delay 100 µs > on delay 10 µs + jump 20 µs: the windows overlap and merge; the laser stays on
// through the jump; a shifted time in the jump reads the previous burst's last power (held).
// With a 1 mm jump (200 µs) the windows stay apart.
TEST(LaserGate, MergesWindowsAcrossAShortJump)
{
  const PathTimeline tl(twoBursts(0.1e-3), kJumpSpeed);  // jump 0.1 mm at 5 m/s = 20 µs
  ASSERT_EQ(tl.segments().size(), 4u);
  const double on = 10e-6;
  const double off = 100e-6;
  const LaserGate gate(tl, on, off);
  ASSERT_EQ(gate.windows().size(), 1u);
  const LaserWindow& w = gate.windows()[0];
  EXPECT_EQ(w.first_segment, 0u);
  EXPECT_EQ(w.end_segment, 4u);
  EXPECT_EQ(w.on_s, 0.0 + on);
  EXPECT_EQ(w.off_s, tl.duration() + off);
  EXPECT_EQ(w.burst_end_s, tl.duration());
  const double b2 = tl.segments()[2].t_start_s;
  const double b3 = tl.segments()[3].t_start_s;
  LaserGate::Cursor c;
  for (double t = on; t < w.off_s; t += 1e-6)
  {
    EXPECT_GT(gate.powerAt(t, c), 0.0) << t;
  }
  EXPECT_EQ(gate.powerAt(tl.segmentEnd(0) + on + 5e-6, c), 100.0);  // shifted time in the jump: held
  EXPECT_EQ(gate.powerAt(before(b2 + on), c), 100.0);
  EXPECT_EQ(gate.powerAt(b2 + on, c), 200.0);
  EXPECT_EQ(gate.powerAt(b3 + on, c), 150.0);  // contiguous marks: one burst, the power changes
  EXPECT_EQ(gate.speedAt(b3 + on, c), 0.8);
  EXPECT_EQ(gate.powerAt(before(w.off_s), c), 150.0);

  const PathTimeline apart(twoBursts(1e-3), kJumpSpeed);  // jump 200 µs
  const LaserGate gate2(apart, on, off);
  ASSERT_EQ(gate2.windows().size(), 2u);
  EXPECT_EQ(gate2.windows()[0].off_s, apart.segmentEnd(0) + off);
  EXPECT_EQ(gate2.windows()[1].on_s, apart.segments()[2].t_start_s + on);
  LaserGate::Cursor c2;
  EXPECT_EQ(gate2.powerAt(apart.segmentEnd(0) + off, c2), 0.0);
}

// on − off >= burst length: the window is empty and lights nothing (left out of windows()); the
// longer burst of the same timeline still lights.
TEST(LaserGate, EmptyWindowLightsNothing)
{
  // mark A lasts 500 µs, marks B+C 300 + 375 = 675 µs
  const PathTimeline tl(twoBursts(1e-3), kJumpSpeed);
  const LaserGate gate(tl, 700e-6, 100e-6);  // on − off = 600 µs: A (500 µs) empty, B+C (675 µs) not
  ASSERT_EQ(gate.windows().size(), 1u);
  EXPECT_EQ(gate.windows()[0].first_segment, 2u);
  LaserGate::Cursor c;
  for (double t = -1e-3; t < tl.segments()[2].t_start_s + 700e-6; t += 1e-6)
  {
    EXPECT_EQ(gate.powerAt(t, c), 0.0) << t;
  }
  EXPECT_EQ(gate.powerAt(tl.segments()[2].t_start_s + 700e-6, c), 200.0);  // B's start, shifted by 700 µs
  const LaserGate none(tl, 800e-6, 0.0);
  EXPECT_TRUE(none.windows().empty());
  LaserGate::Cursor c2;
  EXPECT_EQ(none.powerAt(1e-3, c2), 0.0);
  EXPECT_EQ(none.speedAt(1e-3, c2), 0.0);
  EXPECT_THROW(LaserGate(tl, std::nan(""), 0.0), scanhead::ConfigError);
}

// A reader that keeps its cursor across chunks of 1, 7 and 1000 samples gets bit for bit what a
// fresh cursor gets at every sample, and what a brute-force linear scan gets (power and speed);
// a backwards reader too. Timeline: marks with several powers and speeds, a dwell, jumps, a
// merged pair of windows; delays 37 µs / 84.5 µs, sampled at 10 µs, 3 µs offset.
TEST(LaserGate, CursorReadersMatchFreshEvaluation)
{
  Job job = twoBursts(0.2e-3);  // 40 µs jump: windows merge (84.5 > 37 + 40)
  scanhead::Polyline spot = line(PolylineType::Mark, 0.0, 60.0, {{2e-3, 1e-3}});
  spot.dwell_s = 0.25e-3;
  job.polylines.push_back(spot);  // implicit jump to it
  job.polylines.push_back(line(PolylineType::Mark, 1.3, 120.0, {{2e-3, 1e-3}, {2.4e-3, 1.2e-3}, {2.1e-3, 1.6e-3}}));
  job.polylines.push_back(line(PolylineType::Jump, 6.0, 0.0, {{2.1e-3, 1.6e-3}, {0, 0}}));
  const PathTimeline tl(job, kJumpSpeed);
  const double on = 37e-6;
  const LaserGate gate(tl, on, 84.5e-6);
  ASSERT_EQ(gate.windows().size(), 2u);  // A+B+C merged; dwell + mark after the implicit jump

  std::vector<double> times;
  for (double t = -3e-5 + 3e-6; t < tl.duration() + 2e-4; t += 1e-5)
    times.push_back(t);
  std::vector<double> fresh_power(times.size());
  std::vector<double> fresh_speed(times.size());
  int lit = 0;
  for (std::size_t i = 0; i < times.size(); ++i)
  {
    LaserGate::Cursor c;
    fresh_power[i] = gate.powerAt(times[i], c);
    LaserGate::Cursor c2;
    fresh_speed[i] = gate.speedAt(times[i], c2);
    EXPECT_EQ(fresh_power[i], bruteForcePower(gate, tl, on, times[i], false)) << times[i];
    EXPECT_EQ(fresh_speed[i], bruteForcePower(gate, tl, on, times[i], true)) << times[i];
    lit += fresh_power[i] > 0.0 ? 1 : 0;
  }
  EXPECT_GT(lit, 150);
  for (const std::size_t chunk : {std::size_t(1), std::size_t(7), std::size_t(1000)})
  {
    LaserGate::Cursor power_cursor;
    LaserGate::Cursor speed_cursor;
    for (std::size_t begin = 0; begin < times.size(); begin += chunk)
    {
      for (std::size_t i = begin; i < std::min(begin + chunk, times.size()); ++i)
      {
        ASSERT_EQ(gate.powerAt(times[i], power_cursor), fresh_power[i]) << chunk << " " << i;
        ASSERT_EQ(gate.speedAt(times[i], speed_cursor), fresh_speed[i]) << chunk << " " << i;
      }
    }
  }
  LaserGate::Cursor back;
  for (std::size_t i = times.size(); i-- > 0;)
  {
    ASSERT_EQ(gate.powerAt(times[i], back), fresh_power[i]) << i;
  }
}

// speedAt reads the programmed speed of the segment powerAt reads (shifted by the on delay); a
// dwell has speed 0; outside windows 0.
TEST(LaserGate, SpeedAtFollowsTheShiftedSegments)
{
  const PathTimeline tl(twoBursts(1e-3), kJumpSpeed);
  const double on = 120e-6;
  const LaserGate gate(tl, on, 30e-6);
  LaserGate::Cursor c;
  EXPECT_EQ(gate.speedAt(on, c), 1.0);
  const double b3 = tl.segments()[3].t_start_s;
  EXPECT_EQ(gate.speedAt(before(b3 + on), c), 2.0);  // the NC is already on C, the laser still on B
  EXPECT_EQ(gate.speedAt(b3 + on, c), 0.8);
  EXPECT_EQ(gate.speedAt(tl.duration() + 29e-6, c), 0.8);  // clamped to the last segment
  EXPECT_EQ(gate.speedAt(tl.duration() + 30e-6, c), 0.0);

  Job job;
  scanhead::Polyline spot = line(PolylineType::Mark, 0.0, 60.0, {{0, 0}});
  spot.dwell_s = 1e-4;
  job.polylines.push_back(spot);
  const PathTimeline dwell(job, kJumpSpeed);
  const LaserGate g2(dwell, 0.0, 0.0);
  LaserGate::Cursor c2;
  EXPECT_EQ(g2.powerAt(5e-5, c2), 60.0);
  EXPECT_EQ(g2.speedAt(5e-5, c2), 0.0);
}
