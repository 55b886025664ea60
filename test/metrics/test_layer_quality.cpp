/// \file test_layer_quality.cpp
/// \brief Layer metrics against closed forms and an independent brute force: both contour-error
/// definitions, the same-instant pairing, gaps, fill rate, angle and speed histograms.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "scanhead/common/segment_distance.hpp"
#include "scanhead/metrics/first_nearest.hpp"
#include "scanhead/metrics/layer_quality.hpp"

using scanhead::ContourErrorStats;
using scanhead::EnergyConfig;
using scanhead::Job;
using scanhead::LayerQuality;
using scanhead::LayerQualityReport;
using scanhead::PathTimeline;
using scanhead::Polyline;
using scanhead::PolylineRole;
using scanhead::PolylineType;
using scanhead::SpotChunk;
using scanhead::SpotSample;

namespace
{
constexpr double kTs = 1e-5;

Polyline line(PolylineType type, PolylineRole role, double speed, std::vector<Eigen::Vector2d> points)
{
  Polyline p;
  p.type = type;
  p.role = role;
  p.speed_mps = speed;
  p.power_w = type == PolylineType::Mark ? 100.0 : 0.0;
  p.points = std::move(points);
  return p;
}

/// A contour square (2 mm, 1 m/s), a jump, a hatch stroke back and forth (0.5 m/s).
Job squareJob()
{
  Job job;
  job.name = "square";
  job.polylines.push_back(
      line(PolylineType::Mark, PolylineRole::Contour, 1.0, {{0, 0}, {2e-3, 0}, {2e-3, 2e-3}, {0, 2e-3}, {0, 0}}));
  job.polylines.push_back(line(PolylineType::Jump, PolylineRole::Unspecified, 4.0, {{0, 0}, {0.2e-3, 0.2e-3}}));
  job.polylines.push_back(line(PolylineType::Mark, PolylineRole::Hatch, 0.5,
                               {{0.2e-3, 0.2e-3}, {1.8e-3, 0.2e-3}, {1.8e-3, 0.3e-3}, {0.2e-3, 0.3e-3}}));
  return job;
}

/// The actual stream: the commanded path L samples late, shifted by \p offset, its last point
/// held for \p tail samples; laser on where the command (L samples earlier) is a mark.
struct Stream
{
  std::vector<SpotSample> samples;
};

Stream delayedStream(const PathTimeline& timeline, int lag, const Eigen::Vector2d& offset, int tail = 50)
{
  Stream s;
  PathTimeline::Cursor cursor;
  const auto n = static_cast<int>(std::ceil(timeline.duration() / kTs)) + lag + tail;
  for (int k = 0; k < n; ++k)
  {
    const double t = (k - lag) * kTs;
    SpotSample sample;
    sample.actual = timeline.positionAt(t, cursor) + offset;
    sample.setpoint = sample.actual;
    sample.power_w = timeline.powerAt(t, cursor);
    sample.angle_error = Eigen::Vector2d(1e-5, -2e-5);
    s.samples.push_back(sample);
  }
  return s;
}

/// delayedStream 13 samples late, shifted by (2, −3) µm, with Gaussian noise of 4 µm on each axis (seeded).
Stream noisyStream(const PathTimeline& timeline, unsigned seed)
{
  Stream s = delayedStream(timeline, 13, Eigen::Vector2d(2e-6, -3e-6));
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, 4e-6);
  for (SpotSample& sample : s.samples)
    sample.actual += Eigen::Vector2d(noise(rng), noise(rng));
  return s;
}

LayerQualityReport run(const PathTimeline& timeline, const Job& job, const Stream& s, double lag_s, std::size_t chunk,
                       const EnergyConfig& config = EnergyConfig(), std::size_t drop_from = 0, std::size_t drop_to = 0,
                       unsigned threads = 1)
{
  LayerQuality q(config, timeline, job, lag_s, s.samples.size(), Eigen::Vector2d(-1e-3, -1e-3),
                 Eigen::Vector2d(3e-3, 3e-3));
  auto send = [&](std::size_t from, std::size_t to) {
    if (from >= to)
      return;
    SpotChunk c;
    c.first_index = from;
    c.period_s = kTs;
    c.samples.assign(s.samples.begin() + static_cast<std::ptrdiff_t>(from),
                     s.samples.begin() + static_cast<std::ptrdiff_t>(to));
    q.process(c);
  };
  for (std::size_t start = 0; start < s.samples.size(); start += chunk)
  {
    const std::size_t end = std::min(s.samples.size(), start + chunk);
    // The samples [drop_from, drop_to) never arrive: a gap in the stream.
    send(start, std::min(end, std::max(start, drop_from)));
    send(std::max(start, std::min(end, drop_to)), end);
  }
  return q.finish(threads);
}

/// The default settings with the same-instant search half-width \p window_s.
EnergyConfig sameInstantWindow(double window_s)
{
  EnergyConfig config;
  config.same_instant_window_s = window_s;
  return config;
}
}  // namespace

// An actual path that is the command shifted by d (and delayed by the lag the metrics compensate):
// every same-instant error is d on the straight legs; at the corners the shifted square lies
// within d too, so every point is at most d and the interior of the legs exactly d.
TEST(LayerQuality, ShiftedPathGivesTheShift)
{
  const Job job = squareJob();
  const PathTimeline timeline(job, 4.0);
  const double d = 15e-6;
  const Stream s = delayedStream(timeline, 20, Eigen::Vector2d(0.0, d));
  const LayerQualityReport r = run(timeline, job, s, 20 * kTs, 1000);
  EXPECT_EQ(r.commanded_points, static_cast<std::uint64_t>(std::ceil(timeline.duration() / kTs - 1e-9)));
  EXPECT_EQ(r.unmatched_points, 0u);
  EXPECT_EQ(r.same_instant.mark.count() + r.same_instant.jump.count(), r.commanded_points);
  EXPECT_EQ(r.same_instant.contour.count() + r.same_instant.hatch.count(), r.same_instant.mark.count());
  ASSERT_GT(r.same_instant.contour.count(), 700u);  // 8 mm at 1 m/s
  ASSERT_GT(r.same_instant.hatch.count(), 300u);
  // Shift along y: the horizontal legs are d away, the vertical legs 0 (the shift runs along them).
  EXPECT_NEAR(r.same_instant.contour.max(), d, 1e-12);
  EXPECT_NEAR(r.nearest_path.contour.max(), d, 1e-8);  // float storage of the path: 3e-8 m at most
  EXPECT_EQ(r.same_instant.contour.shareUnder(20e-6), 1.0);
  EXPECT_EQ(r.same_instant.contour.shareUnder(10e-6) < 1.0, true);
  // (a) ≤ (b) point by point, so its share under any limit is at least (b)'s.
  EXPECT_GE(r.nearest_path.mark.shareUnder(10e-6), r.same_instant.mark.shareUnder(10e-6));
  EXPECT_TRUE(r.nearest_measured);
  // Angle errors: one per program sample; speed ratio 1 on the marks.
  EXPECT_EQ(r.angle_error_x.count(), r.commanded_points);
  EXPECT_NEAR(r.angle_error_x.mean(), 1e-5, 1e-12);
  EXPECT_NEAR(r.mark_speed_mean_ratio, 1.0, 0.02);
  EXPECT_DOUBLE_EQ(r.layer_time_s, timeline.duration());
}

// A lag the pairing misses: the strict same instant (window 0) sees it as error (20 samples at
// 1 m/s: 200 µm behind, minus the adjacent 10 µm segment = 190 µm); the search window of ±N
// samples absorbs up to N samples of it (the least following error); nearest path never sees it.
TEST(LayerQuality, SameInstantNeedsTheLagOrItsWindow)
{
  const Job job = squareJob();
  const PathTimeline timeline(job, 4.0);
  const Stream s = delayedStream(timeline, 20, Eigen::Vector2d::Zero());
  const EnergyConfig strict = sameInstantWindow(0.0);
  const LayerQualityReport r = run(timeline, job, s, 0.0, 1000, strict);
  EXPECT_NEAR(r.same_instant.contour.quantileUpperBound(0.5), 190e-6, 1e-6);
  EXPECT_LT(r.nearest_path.contour.max(), 1e-8);
  EXPECT_EQ(r.window_s, 0.0);
  const LayerQualityReport wide = run(timeline, job, s, 0.0, 1000);  // default ±200 µs = ±20 samples
  EXPECT_DOUBLE_EQ(wide.window_s, 200e-6);
  EXPECT_LT(wide.same_instant.contour.quantileUpperBound(0.9), 1e-6);
  // 15 of the 20 samples: 5 left, 50 µm − 10 µm = 40 µm
  const LayerQualityReport part = run(timeline, job, s, 0.0, 1000, sameInstantWindow(150e-6));
  EXPECT_NEAR(part.same_instant.contour.quantileUpperBound(0.5), 40e-6, 1e-6);
}

// Definition (a) against an independent brute force (every actual segment, double precision) on a
// noisy, lagged path with a cut corner; both definitions independent of the chunking.
TEST(LayerQuality, NearestPathMatchesBruteForceAndChunking)
{
  const Job job = squareJob();
  const PathTimeline timeline(job, 4.0);
  const Stream s = noisyStream(timeline, 7);
  const LayerQualityReport r = run(timeline, job, s, 13 * kTs, 1000);
  ContourErrorStats brute;
  PathTimeline::Cursor cursor;
  double max_brute = 0.0;
  for (std::uint64_t k = 0; k < r.commanded_points; ++k)
  {
    const Eigen::Vector2d c = timeline.positionAt(static_cast<double>(k) * kTs, cursor);
    double best = INFINITY;
    for (std::size_t j = 0; j + 1 < s.samples.size(); ++j)
      best = std::min(best, scanhead::pointSegmentDistance(c, s.samples[j].actual, s.samples[j + 1].actual));
    max_brute = std::max(max_brute, best);
    brute.add(best);
  }
  const ContourErrorStats all = [&] {
    ContourErrorStats merged = r.nearest_path.mark;
    merged.merge(r.nearest_path.jump);
    return merged;
  }();
  EXPECT_EQ(all.count(), brute.count());
  EXPECT_NEAR(all.max(), max_brute, 1e-8);
  EXPECT_NEAR(all.mean(), brute.mean(), 1e-8);
  for (double limit : {5e-6, 10e-6, 20e-6})
    EXPECT_NEAR(all.shareUnder(limit), brute.shareUnder(limit), 2.0 / static_cast<double>(brute.count()));
  for (std::size_t chunk : {1u, 7u})
  {
    const LayerQualityReport other = run(timeline, job, s, 13 * kTs, chunk);
    EXPECT_TRUE(other.same_instant.mark == r.same_instant.mark) << "chunk " << chunk;
    EXPECT_TRUE(other.nearest_path.mark == r.nearest_path.mark) << "chunk " << chunk;
    EXPECT_EQ(other.fill_cells_reached, r.fill_cells_reached);
    EXPECT_EQ(other.mark_speed_ratio.binCounts(), r.mark_speed_ratio.binCounts());
  }
}

// The nearest-path pass on two threads (its queries in blocks of 2^15, halves on a side thread, added in order) gives
// the same figures, bit for bit, as one thread: a meander long enough for several blocks (~120 000 points).
TEST(LayerQuality, NearestPathOnTwoThreadsEqualsOne)
{
  Job job;
  job.name = "meander";
  std::vector<Eigen::Vector2d> points;
  for (int i = 0; i < 300; ++i)
  {
    const double y = i * 5e-6;
    points.emplace_back(i % 2 ? 2e-3 : 0.0, y);
    points.emplace_back(i % 2 ? 0.0 : 2e-3, y);
  }
  job.polylines.push_back(line(PolylineType::Mark, PolylineRole::Hatch, 0.5, std::move(points)));
  const PathTimeline timeline(job, 4.0);
  const Stream s = noisyStream(timeline, 11);
  const LayerQualityReport one = run(timeline, job, s, 13 * kTs, 1000);
  const LayerQualityReport two = run(timeline, job, s, 13 * kTs, 1000, EnergyConfig(), 0, 0, 2);
  ASSERT_GT(one.commanded_points, 3u << 15);
  ASSERT_TRUE(one.nearest_measured);
  EXPECT_TRUE(two.nearest_path.mark == one.nearest_path.mark);
  EXPECT_TRUE(two.nearest_path.hatch == one.nearest_path.hatch);
  EXPECT_TRUE(two.nearest_path.jump == one.nearest_path.jump);
  EXPECT_EQ(two.nearest_path.mark.count(), one.nearest_path.mark.count());
  EXPECT_GT(one.nearest_path.mark.count(), 0u);
}

// A lost stretch of the stream (100 samples): the commanded points whose whole search window lies
// in it are counted as unmatched (100 − 2N: N = 20 by default, 0 strict), nothing silently
// vanishes, and the path is not joined across the gap.
TEST(LayerQuality, GapsAreCountedNotHidden)
{
  const Job job = squareJob();
  const PathTimeline timeline(job, 4.0);
  const Stream s = delayedStream(timeline, 10, Eigen::Vector2d::Zero());
  const EnergyConfig strict = sameInstantWindow(0.0);
  for (const EnergyConfig& config : {EnergyConfig(), strict})
  {
    const LayerQualityReport r = run(timeline, job, s, 10 * kTs, 1000, config, 300, 400);
    const auto n = static_cast<std::uint64_t>(std::llround(config.same_instant_window_s / kTs));
    EXPECT_EQ(r.unmatched_points, 100u - 2 * n);
    EXPECT_EQ(r.same_instant.mark.count() + r.same_instant.jump.count() + r.unmatched_points, r.commanded_points);
    EXPECT_EQ(r.nearest_path.mark.count() + r.nearest_path.jump.count(), r.commanded_points);
  }
}

// Fill rate: a perfect machine fills 100 % of the hatch cells; a hatch displaced by 3 spot
// diameters reaches none of them. Beyond energy.contour_max_samples (a) is skipped, (b) is not.
TEST(LayerQuality, FillRateAndTheNearestPathCap)
{
  const Job job = squareJob();
  const PathTimeline timeline(job, 4.0);
  const LayerQualityReport perfect =
      run(timeline, job, delayedStream(timeline, 5, Eigen::Vector2d::Zero()), 5 * kTs, 1000);
  EXPECT_GT(perfect.fill_cells_to_fill, 40u);
  EXPECT_DOUBLE_EQ(perfect.fill_rate, 1.0);
  const LayerQualityReport off =
      run(timeline, job, delayedStream(timeline, 5, Eigen::Vector2d(0.0, 0.5e-3)), 5 * kTs, 1000);
  EXPECT_EQ(off.fill_cells_to_fill, perfect.fill_cells_to_fill);
  EXPECT_DOUBLE_EQ(off.fill_rate, 0.0);
  EnergyConfig capped;
  capped.contour_max_samples = 100;
  const LayerQualityReport r =
      run(timeline, job, delayedStream(timeline, 5, Eigen::Vector2d::Zero()), 5 * kTs, 1000, capped);
  EXPECT_FALSE(r.nearest_measured);
  EXPECT_EQ(r.nearest_path.mark.count(), 0u);
  EXPECT_GT(r.same_instant.mark.count(), 0u);
}

// firstNearest (the same-instant search) against the loop it stands for: random windows of 0–59 samples with exact
// ties (repeated points, a commanded point on them), NaN and infinite coordinates, every length's remainder.
TEST(LayerQuality, FirstNearestIsTheLoopsFirstSmallest)
{
  std::mt19937 rng(12);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::uniform_int_distribution<int> pick(0, 9);
  std::vector<double> x(64), y(64);
  std::size_t ties = 0;
  for (int trial = 0; trial < 200000; ++trial)
  {
    const std::size_t n = static_cast<std::size_t>(trial % 60);
    for (std::size_t i = 0; i < n; ++i)
    {
      const int q = pick(rng);
      x[i] = q < 3 ? 0.25 * q : u(rng);  // three repeated points: ties
      y[i] = q < 3 ? 0.5 : u(rng);
      if (q == 9 && trial % 7 == 0)
        x[i] = NAN;
      if (q == 8 && trial % 11 == 0)
        y[i] = INFINITY;
    }
    const double cx = pick(rng) < 5 ? 0.25 : u(rng), cy = 0.5;
    double expected_d2 = INFINITY;
    std::size_t expected = 0, equal = 0;
    for (std::size_t i = 0; i < n; ++i)
    {
      const double dx = x[i] - cx, dy = y[i] - cy, d2 = dx * dx + dy * dy;
      if (d2 < expected_d2)
      {
        expected_d2 = d2;
        expected = i;
      }
    }
    for (std::size_t i = 0; i < n; ++i)
    {
      const double dx = x[i] - cx, dy = y[i] - cy;
      equal += dx * dx + dy * dy == expected_d2 ? 1 : 0;
    }
    ties += equal > 1 ? 1 : 0;
    double d2 = 0.0;
    ASSERT_EQ(scanhead::firstNearest(x.data(), y.data(), n, cx, cy, d2), expected) << trial;
    ASSERT_EQ(d2, expected_d2) << trial;
  }
  EXPECT_GT(ties, 10000u);
}
