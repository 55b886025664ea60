/// \file test_laser_placement.cpp
/// \brief Laser-on samples off the marked path: grid distances against brute force (SPEC §2.5).
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iostream>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "fixtures/polyline_fixture.hpp"
#include "scanhead/common/errors.hpp"
#include "scanhead/job/generators/thesis_square_job.hpp"
#include "scanhead/metrics/laser_placement.hpp"

using scanhead::ConfigError;
using scanhead::Job;
using scanhead::LaserPlacement;
using scanhead::LaserPlacementCounts;
using scanhead::PolylineType;
using scanhead::SpotChunk;
using scanhead::SpotSample;
using scanhead::test_support::line;

namespace
{
constexpr double kTol = 50e-6;  // [m]
constexpr double kInf = std::numeric_limits<double>::infinity();
using V = Eigen::Vector2d;

double mm(double x)
{
  return x * 1e-3;
}

/// \brief A 10 mm square contour, four horizontal hatch lines, one 45° hatch line, a dwell at
/// (15, 5) mm, and a jump along x = 20 mm that is not a mark.
Job squareAndHatch()
{
  Job job;
  job.polylines.push_back(
      line(PolylineType::Mark, 1.5, 200, {V(0, 0), V(mm(10), 0), V(mm(10), mm(10)), V(0, mm(10)), V(0, 0)}));
  for (double y : {2.0, 4.0, 6.0, 8.0})
    job.polylines.push_back(line(PolylineType::Mark, 1.0, 200, {V(mm(1), mm(y)), V(mm(9), mm(y))}));
  job.polylines.push_back(line(PolylineType::Mark, 1.0, 200, {V(mm(1), mm(1.5)), V(mm(3), mm(3.5))}));
  job.polylines.push_back(line(PolylineType::Jump, 6.0, 0, {V(mm(20), 0), V(mm(20), mm(10))}));
  auto dwell = line(PolylineType::Mark, 1.0, 200, {V(mm(15), mm(5))});
  dwell.dwell_s = 1e-3;
  job.polylines.push_back(dwell);
  return job;
}

/// \brief Point–segment distance, written independently of the implementation (Eigen, projection).
double segmentDistance(const V& p, const V& a, const V& b)
{
  const V ab = b - a;
  const double len2 = ab.squaredNorm();
  if (len2 == 0.0)
    return (p - a).norm();
  const double t = std::clamp((p - a).dot(ab) / len2, 0.0, 1.0);
  return (p - (a + t * ab)).norm();
}

/// \brief Minimum over every MARK segment and dwell of \p job.
double bruteDistance(const Job& job, const V& p)
{
  double best = kInf;
  for (const auto& pl : job.polylines)
  {
    if (pl.type != PolylineType::Mark)
      continue;
    if (pl.points.size() == 1)
      best = std::min(best, (p - pl.points[0]).norm());
    for (std::size_t k = 1; k < pl.points.size(); ++k)
      best = std::min(best, segmentDistance(p, pl.points[k - 1], pl.points[k]));
  }
  return best;
}

SpotSample spot(const V& p, double power)
{
  SpotSample s;
  s.actual = p;
  s.setpoint = p;
  s.power_w = power;
  return s;
}

LaserPlacementCounts feed(LaserPlacement& lp, const std::vector<SpotSample>& s, std::size_t chunk, double period)
{
  for (std::size_t start = 0; start < s.size(); start += chunk)
  {
    SpotChunk c;
    c.first_index = start;
    c.period_s = period;
    c.samples.assign(s.begin() + static_cast<std::ptrdiff_t>(start),
                     s.begin() + static_cast<std::ptrdiff_t>(std::min(s.size(), start + chunk)));
    lp.add(c);
  }
  return lp.counts();
}
}  // namespace

// Points at known distances from the contour, the hatch and the dwell.
TEST(LaserPlacement, KnownDistances)
{
  const Job job = squareAndHatch();
  const LaserPlacement lp(job, kTol);
  EXPECT_EQ(lp.cellSide(), 1e-3);  // max(50 µm, 1 mm)
  const double eps = 1e-9;
  struct Probe
  {
    V p;
    double d;
  };
  const std::vector<Probe> probes = {
      {V(mm(5), 0), 0.0},                                    // on the contour
      {V(mm(5), -(kTol - eps)), kTol - eps},                 // just inside the tolerance, below the edge
      {V(mm(5), -(kTol + eps)), kTol + eps},                 // just outside
      {V(mm(10) + mm(0.3), mm(7)), mm(0.3)},                 // right of the right edge
      {V(-mm(0.04), -mm(0.04)), std::sqrt(2.0) * mm(0.04)},  // beyond the corner: 56.6 µm, though |dx|, |dy| < tol
      {V(mm(9) + mm(0.045), mm(4)), mm(0.045)},              // past a hatch line's end
      {V(mm(5), mm(3.3)), mm(0.7)},                          // between hatch lines 2 and 4 mm
      {V(mm(2), mm(2.5)), 0.0},                              // on the 45° line
      {V(mm(2.5), mm(2.5)), mm(0.5) / std::sqrt(2.0)},       // beside the 45° line (0.354 mm)
      {V(mm(15.03), mm(5)), mm(0.03)},                       // by the dwell point
      {V(mm(5), mm(10) + mm(0.999)), mm(0.999)},             // just within the reach of one cell
  };
  for (const Probe& q : probes)
  {
    const double d = lp.distanceToMarks(q.p);
    // 1e-15 m: point arithmetic at ~10 mm coordinates (ulp 1.7e-18 m) and a few operations.
    EXPECT_NEAR(d, q.d, 1e-15) << q.p.transpose();
    EXPECT_NEAR(d, bruteDistance(job, q.p), 1e-15) << q.p.transpose();
  }
  // Beyond the reach (one cell): infinity, also far off the grid and on the jump (not a mark).
  EXPECT_EQ(lp.distanceToMarks(V(mm(5), mm(12))), kInf);
  EXPECT_EQ(lp.distanceToMarks(V(mm(20), mm(5))), kInf);
  EXPECT_EQ(lp.distanceToMarks(V(1.0, -2.0)), kInf);
  EXPECT_TRUE(std::isnan(lp.distanceToMarks(V(NAN, 0))));
}

// Off-path counting and energy Σ P·Ts; power-0 samples do not count; max distance is exact also
// beyond the reach; chunks of 1, 7, 1000 give identical counts.
TEST(LaserPlacement, CountsEnergyAndChunks)
{
  const Job job = squareAndHatch();
  const double period = 2e-5;  // 50 kHz, so the chunk period (not 1e-5) must be used
  std::vector<SpotSample> s;
  std::uint64_t on = 0, off = 0;
  double energy = 0.0, max_d = 0.0;
  auto add = [&](const V& p, double power) {
    s.push_back(spot(p, power));
    if (power > 0.0)
    {
      ++on;
      const double d = bruteDistance(job, p);
      max_d = std::max(max_d, d);
      if (d > kTol)
      {
        ++off;
        energy += power * period;
      }
    }
  };
  // Along the contour edge at offsets of 0, 30, 49.9 µm (on), 50.1 µm, 0.2 mm (off), 60 samples each.
  for (double offset : {0.0, 30e-6, 49.9e-6, 50.1e-6, 0.2e-3})
    for (int k = 0; k < 60; ++k)
      add(V(mm(0.5) + k * mm(0.15), -offset), 150.0 + k);
  // Along the jump at x = 20 mm with the laser on (5 mm from the dwell and more): off, beyond reach.
  for (int k = 0; k <= 20; ++k)
    add(V(mm(20), k * mm(0.5)), 100.0);
  // Laser off far away: ignored.
  for (int k = 0; k < 10; ++k)
    add(V(mm(50), mm(50)), 0.0);
  // One far point off the grid: exact distance by the far path.
  add(V(-0.2, 0.1), 10.0);

  std::vector<LaserPlacementCounts> results;
  for (std::size_t chunk : {1u, 7u, 1000u})
  {
    LaserPlacement lp(job, kTol);
    results.push_back(feed(lp, s, chunk, period));
  }
  const LaserPlacementCounts& c = results[0];
  std::cout << "[counts] on " << c.laser_on_samples << ", off " << c.off_path_samples << ", energy "
            << c.off_path_energy_j << " J, max distance " << c.max_distance_m << " m\n";
  EXPECT_EQ(c.laser_on_samples, on);
  EXPECT_EQ(c.laser_on_samples, 5u * 60u + 21u + 1u);
  EXPECT_EQ(c.off_path_samples, off);
  EXPECT_EQ(c.off_path_samples, 2u * 60u + 21u + 1u);
  EXPECT_NEAR(c.off_path_energy_j, energy, 1e-15);
  EXPECT_NEAR(c.max_distance_m, max_d, 1e-15);
  EXPECT_NEAR(c.max_distance_m, std::hypot(0.2, 0.1 - mm(10)), 1e-15);  // nearest mark: the corner (0, 10 mm)
  for (std::size_t i = 1; i < results.size(); ++i)
  {
    EXPECT_EQ(results[i].laser_on_samples, c.laser_on_samples);
    EXPECT_EQ(results[i].off_path_samples, c.off_path_samples);
    EXPECT_EQ(results[i].off_path_energy_j, c.off_path_energy_j);  // bit-identical
    EXPECT_EQ(results[i].max_distance_m, c.max_distance_m);
  }
}

// 10 000 random points (fixed seed) around a job of random segments: the grid answer equals brute
// force wherever brute force is within the reach, and is infinity otherwise; the exact distance
// behind max_distance_m equals brute force everywhere; the on/off classification agrees.
TEST(LaserPlacement, GridEqualsBruteForce)
{
  std::mt19937 rng(20240607);  // fixed seed
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Job job = squareAndHatch();
  for (int k = 0; k < 200; ++k)
  {
    const V a(mm(-5 + 25 * u(rng)), mm(-5 + 20 * u(rng)));
    const double len = mm(0.05 + 6 * u(rng)), ang = 2 * M_PI * u(rng);
    job.polylines.push_back(line(PolylineType::Mark, 1.0, 100, {a, a + len * V(std::cos(ang), std::sin(ang))}));
  }
  for (int k = 0; k < 20; ++k)
    job.polylines.push_back(line(PolylineType::Mark, 1.0, 100, {V(mm(-5 + 25 * u(rng)), mm(-5 + 20 * u(rng)))}));
  const double tol = 80e-6;
  LaserPlacement lp(job, tol);
  const double reach = lp.cellSide();
  int within = 0, beyond = 0;
  double worst = 0.0, running_max = 0.0;
  std::uint64_t off = 0;
  for (int k = 0; k < 10000; ++k)
  {
    // Mostly near the marks: 3/4 of the points within 0.2 mm of a random segment's point.
    V p(mm(-8 + 31 * u(rng)), mm(-8 + 26 * u(rng)));
    if (k % 4 != 3)
    {
      const auto& pl = job.polylines[static_cast<std::size_t>(rng() % job.polylines.size())];
      const V a = pl.points.front(), b = pl.points.back();
      p = a + u(rng) * (b - a) + mm(0.2) * V(2 * u(rng) - 1, 2 * u(rng) - 1);
    }
    const double ref = bruteDistance(job, p);
    const double d = lp.distanceToMarks(p);
    if (ref <= reach)
    {
      ++within;
      worst = std::max(worst, std::abs(d - ref));
    }
    else
    {
      ++beyond;
      EXPECT_EQ(d, kInf) << p.transpose();
    }
    // One sample per add: counts and the exact distance behind max_distance_m.
    SpotChunk c;
    c.first_index = static_cast<std::uint64_t>(k);
    c.samples.push_back(spot(p, 100.0));
    lp.add(c);
    running_max = std::max(running_max, ref);
    off += ref > tol ? 1 : 0;
    ASSERT_NEAR(lp.counts().max_distance_m, running_max, 1e-15) << k;
  }
  std::cout << "[brute] " << within << " points within the reach (" << reach << " m), " << beyond
            << " beyond; worst |grid - brute| " << worst << " m; off path " << off << "\n";
  EXPECT_GT(within, 7000);
  EXPECT_GT(beyond, 100);
  EXPECT_LT(worst, 1e-15);  // same closed form, different rounding: ~1e-19 m
  EXPECT_EQ(lp.counts().off_path_samples, off);
  EXPECT_EQ(lp.counts().laser_on_samples, 10000u);
}

// A smooth stream wandering about the marks (as a lagging, overshooting spot does): most samples
// are settled by the bounds from the previous search, and the counts equal brute force per sample.
TEST(LaserPlacement, SmoothStreamEqualsBruteForce)
{
  const Job job = squareAndHatch();
  std::mt19937 rng(99);  // fixed seed
  std::normal_distribution<double> n01(0.0, 1.0);
  // Along the contour and the hatch lines in turn at 10 µm per sample, with a lateral wander
  // (random walk, 3 µm steps, pulled back to the line) that crosses the tolerance often.
  std::vector<SpotSample> s;
  std::uint64_t off = 0;
  double energy = 0.0, max_d = 0.0;
  auto add = [&](const V& p) {
    s.push_back(spot(p, 180.0));
    const double d = bruteDistance(job, p);
    max_d = std::max(max_d, d);
    if (d > kTol)
    {
      ++off;
      energy += 180.0 * 1e-5;
    }
  };
  // A far sample first: the maximum is large from the start, so later off-path samples are
  // settled by the bounds alone (the lower bound must then be right).
  add(V(-0.2, 0.1));
  double wander = 0.0;
  for (const auto& pl : job.polylines)
  {
    if (pl.type != PolylineType::Mark || pl.points.size() < 2)
      continue;
    for (std::size_t k = 1; k < pl.points.size(); ++k)
    {
      const V a = pl.points[k - 1], b = pl.points[k];
      const V t = (b - a).normalized(), nrm(-t.y(), t.x());
      const int m = static_cast<int>((b - a).norm() / 10e-6);
      for (int i = 0; i < m; ++i)
      {
        wander = 0.97 * wander + 3e-6 * n01(rng);  // stationary spread ~ 3 µm/sqrt(1 − 0.97²) = 12 µm
        const double excursion = (i / 400) % 5 == 4 ? 120e-6 : 0.0;  // every 5th stretch: 120 µm off
        add(a + (b - a) * (double(i) / m) + (3.0 * wander + excursion) * nrm);
      }
    }
  }
  // Straight approaches from empty space across marks at 10 µm per sample, through cell borders:
  // onto the dwell point, across the right contour edge, across hatch lines from between them.
  for (int i = 0; i <= 300; ++i)
    add(V(mm(17.3) - i * 10e-6, mm(5.0004)));  // 2.3 mm → past the dwell point
  for (int i = 0; i <= 300; ++i)
    add(V(mm(12.2) - i * 10e-6, mm(3.3)));  // 2.2 mm right of the edge → 0.8 mm inside
  for (int i = 0; i <= 400; ++i)
    add(V(mm(6.3), mm(0.7) + i * 10e-6));  // crosses the hatch line y = 2 mm and stops short of 4 mm
  LaserPlacement lp(job, kTol);
  const LaserPlacementCounts c = feed(lp, s, 7, 1e-5);
  std::cout << "[smooth] " << s.size() << " samples, off path " << c.off_path_samples << " (brute " << off
            << "), max distance " << c.max_distance_m << " m\n";
  EXPECT_EQ(c.laser_on_samples, s.size());
  EXPECT_EQ(c.off_path_samples, off);
  EXPECT_GT(off, s.size() / 10);  // the stream does cross the tolerance
  EXPECT_LT(off, s.size() * 9 / 10);
  EXPECT_NEAR(c.off_path_energy_j, energy, 1e-12 * energy);  // summation order only
  EXPECT_NEAR(c.max_distance_m, max_d, 1e-15);
}

// The own cell's nearest segment can be farther than a mark in the next cell: its distance is then
// no lower bound. Marks: F along y = 0 (x 0..3 mm) and a dwell N at (1.5, 1.2) mm; cell borders
// at whole mm (grid origin (−1, −1) mm). From (1.5, 0.8) mm the own cell holds only F (0.8 mm) while
// N is 0.4 mm away; the stream walks up onto N after a far sample has made the maximum large.
TEST(LaserPlacement, BoundsAcrossCellBorder)
{
  Job job;
  job.polylines.push_back(line(PolylineType::Mark, 1.0, 100, {V(0, 0), V(mm(3), 0)}));
  job.polylines.push_back(line(PolylineType::Mark, 1.0, 100, {V(mm(1.5), mm(1.2))}));
  LaserPlacement lp(job, kTol);
  std::vector<SpotSample> s = {spot(V(0.1, 0.1), 100.0)};
  for (int i = 0; i <= 60; ++i)
    s.push_back(spot(V(mm(1.5), mm(0.803) + i * 10e-6), 100.0));  // y 0.803 → 1.403 mm (no ties at 50 µm)
  std::uint64_t off = 0;
  for (const SpotSample& q : s)
    off += bruteDistance(job, q.actual) > kTol ? 1 : 0;
  const LaserPlacementCounts c = feed(lp, s, 1000, 1e-5);
  EXPECT_EQ(off, 1u + 61u - 10u);  // y = 1.153 .. 1.243 mm (10 samples) within 50 µm of N
  EXPECT_EQ(c.off_path_samples, off);
  EXPECT_NEAR(c.max_distance_m, bruteDistance(job, V(0.1, 0.1)), 1e-15);
}

// A spot drifting slowly off a line but staying within the tolerance: no sample is off path, and
// max_distance_m follows the drift (the bound that settles on/off must not freeze the maximum).
TEST(LaserPlacement, MaxDistanceFollowsOnPathDrift)
{
  const Job job = squareAndHatch();
  LaserPlacement lp(job, kTol);
  std::vector<SpotSample> s;
  for (int i = 0; i <= 45; ++i)
    s.push_back(spot(V(mm(4) + i * 10e-6, mm(6) + i * 1e-6), 100.0));  // 0 → 45 µm above the hatch y = 6 mm
  const LaserPlacementCounts c = feed(lp, s, 7, 1e-5);
  EXPECT_EQ(c.off_path_samples, 0u);
  EXPECT_NEAR(c.max_distance_m, 45e-6, 1e-15);
}

// The tolerance must be finite and > 0; a job without marks has every laser-on sample off path.
TEST(LaserPlacement, BadToleranceAndNoMarks)
{
  const Job job = squareAndHatch();
  auto message = [&](double tol) {
    try
    {
      LaserPlacement lp(job, tol);
    }
    catch (const ConfigError& e)
    {
      return std::string(e.what());
    }
    return std::string("no throw");
  };
  EXPECT_EQ(message(0.0), "laser_placement.tolerance_m must be > 0 (got 0)");
  EXPECT_EQ(message(-1e-5), "laser_placement.tolerance_m must be > 0 (got -1e-05)");
  EXPECT_EQ(message(NAN), "laser_placement.tolerance_m must be > 0 (got nan)");
  EXPECT_EQ(message(INFINITY), "laser_placement.tolerance_m must be finite (got inf)");
  // A tolerance above 1 mm sets the cell side.
  EXPECT_EQ(LaserPlacement(job, 2.5e-3).cellSide(), 2.5e-3);

  Job jumps_only;
  jumps_only.polylines.push_back(line(PolylineType::Jump, 6.0, 0, {V(0, 0), V(mm(10), 0)}));
  LaserPlacement lp(jumps_only, kTol);
  EXPECT_EQ(lp.distanceToMarks(V(mm(5), 0)), kInf);  // on the jump: not a mark
  SpotChunk c;
  c.samples = {spot(V(mm(5), 0), 100.0), spot(V(0, 0), 0.0)};
  lp.add(c);
  EXPECT_EQ(lp.counts().laser_on_samples, 1u);
  EXPECT_EQ(lp.counts().off_path_samples, 1u);
  EXPECT_EQ(lp.counts().max_distance_m, kInf);

  LaserPlacement ok(job, kTol);
  c.samples = {spot(V(NAN, 0), 100.0)};
  EXPECT_THROW(ok.add(c), scanhead::NumericalError);
}

// The default THESIS job (300 squares, 45° hatch at 100 µm): built quickly, and the grid agrees
// with brute force at random points near the marks; every vertex of every mark is on path.
TEST(LaserPlacement, ThesisJobScale)
{
  const Job job = scanhead::makeThesisSquareJob(scanhead::SquareJobParams(), 1);
  std::size_t segments = 0;
  for (const auto& pl : job.polylines)
    if (pl.type == PolylineType::Mark)
      segments += pl.points.size() > 1 ? pl.points.size() - 1 : 1;
  const auto t0 = std::chrono::steady_clock::now();
  LaserPlacement lp(job, 20e-6);
  const auto t1 = std::chrono::steady_clock::now();

  // On path: every vertex of every MARK polyline.
  SpotChunk c;
  for (const auto& pl : job.polylines)
    if (pl.type == PolylineType::Mark)
      for (const V& p : pl.points)
        c.samples.push_back(spot(p, 200.0));
  lp.add(c);
  const auto t2 = std::chrono::steady_clock::now();
  EXPECT_EQ(lp.counts().off_path_samples, 0u);
  EXPECT_EQ(lp.counts().max_distance_m, 0.0);

  // 200 random points near random vertices: grid = brute force (each brute force is 85k segments).
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  double worst = 0.0;
  int within = 0;
  for (int k = 0; k < 200; ++k)
  {
    const V p = c.samples[rng() % c.samples.size()].actual + mm(0.3) * V(u(rng), u(rng));
    const double ref = bruteDistance(job, p);
    const double d = lp.distanceToMarks(p);
    if (ref <= lp.cellSide())
    {
      ++within;
      worst = std::max(worst, std::abs(d - ref));
    }
    else
      EXPECT_EQ(d, kInf);
  }
  const double build_s = std::chrono::duration<double>(t1 - t0).count();
  const double per_vertex_ns = 1e9 * std::chrono::duration<double>(t2 - t1).count() / double(c.samples.size());
  std::cout << "[thesis] " << segments << " mark segments, build " << build_s << " s, " << per_vertex_ns
            << " ns per vertex (each a search), " << within << " of 200 within reach, worst |grid - brute| " << worst
            << " m\n";
  EXPECT_GT(segments, 50000u);
  EXPECT_EQ(within, 200);
  EXPECT_LT(worst, 1e-15);
}
