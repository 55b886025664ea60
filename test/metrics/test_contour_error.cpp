/// \file test_contour_error.cpp
/// \brief Contour error, both definitions of SPEC §5, against brute force and closed forms; the
/// statistics; the index's work per query as the path grows (not a timed test).
///
/// Tolerances: index vs brute force 1e-12 m (both read the same stored points; they differ only by
/// the rounding of the box bounds and the orientation of duplicate segments, ~1e-17 m). Closed
/// forms on dyadic coordinates (exact in float) 1e-15 m; on other coordinates 5e-10 m (half a float
/// ulp at 5 mm from the origin is 2.3e-10 m).
/// Seeded sweeps: CONTOUR_ERROR_SEED (default 20240611) and CONTOUR_ERROR_CASES (default 40) from
/// the environment, e.g. `CONTOUR_ERROR_SEED=7 CONTOUR_ERROR_CASES=400 test_contour_error`.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "scanhead/common/errors.hpp"
#include "scanhead/metrics/contour_error.hpp"

using Eigen::Vector2d;
using scanhead::ContourErrorStats;
using scanhead::InputError;
using scanhead::nearestPathDistanceBruteForce;
using scanhead::NearestPathHint;
using scanhead::NearestPathIndex;
using scanhead::NearestPathWork;
using scanhead::NumericalError;
using scanhead::PathPoints;
using scanhead::sameInstantDistance;

namespace
{
constexpr double kIndexTolerance = 1e-12;   // index vs brute force [m]
constexpr double kDyadicTolerance = 1e-15;  // closed forms on float-exact points [m]
constexpr double kFloatTolerance = 5e-10;   // closed forms with float-rounded points within 5 mm [m]

std::uint64_t envNumber(const char* name, std::uint64_t fallback)
{
  const char* v = std::getenv(name);
  return v && *v ? std::strtoull(v, nullptr, 10) : fallback;
}

std::uint64_t seed()
{
  return envNumber("CONTOUR_ERROR_SEED", 20240611);
}

int cases()
{
  return static_cast<int>(envNumber("CONTOUR_ERROR_CASES", 40));
}

/// Independent point-segment distance (projection onto the line, then clamped by comparing with
/// both ends), not segment_distance.hpp's formula.
double referenceSegmentDistance(const Vector2d& p, const Vector2d& a, const Vector2d& b)
{
  const Vector2d d = b - a;
  const double dot_a = (p - a).dot(d);
  const double dot_b = (p - b).dot(-d);
  if (d.squaredNorm() == 0.0 || dot_a <= 0.0)
    return std::hypot(p.x() - a.x(), p.y() - a.y());
  if (dot_b <= 0.0)
    return std::hypot(p.x() - b.x(), p.y() - b.y());
  const double cross = d.x() * (p.y() - a.y()) - d.y() * (p.x() - a.x());
  return std::abs(cross) / std::hypot(d.x(), d.y());
}

/// The path's segments (and isolated points as zero-length segments), read from the stored points.
std::vector<std::pair<Vector2d, Vector2d>> segmentsOf(const PathPoints& path)
{
  std::vector<std::pair<Vector2d, Vector2d>> s;
  for (std::size_t i = 0; i < path.size(); ++i)
  {
    if (path.joinsNext(i))
      s.emplace_back(path.point(i), path.point(i + 1));
    else if (i == 0 || !path.joinsNext(i - 1))
      s.emplace_back(path.point(i), path.point(i));
  }
  return s;
}

double referenceNearest(const std::vector<std::pair<Vector2d, Vector2d>>& segments, const Vector2d& p)
{
  double best = std::numeric_limits<double>::infinity();
  for (const auto& s : segments)
    best = std::min(best, referenceSegmentDistance(p, s.first, s.second));
  return best;
}

/// Same instant by a loop over all segments, keeping those that touch sample j.
double referenceSameInstant(const PathPoints& path, std::size_t j, const Vector2d& p)
{
  double best = std::numeric_limits<double>::infinity();
  bool any = false;
  for (std::size_t i = 0; i + 1 < path.size(); ++i)
  {
    if ((i == j || i + 1 == j) && path.joinsNext(i))
    {
      best = std::min(best, referenceSegmentDistance(p, path.point(i), path.point(i + 1)));
      any = true;
    }
  }
  return any ? best : (path.point(j) - p).norm();
}

enum class Kind
{
  RandomWalk,
  DenseZigZag,
  WithBreaks,
  AtRest,
  SparseField,
  LongSegments,
  Count
};

const char* kindName(Kind k)
{
  switch (k)
  {
    case Kind::RandomWalk:
      return "random walk";
    case Kind::DenseZigZag:
      return "dense zig-zag";
    case Kind::WithBreaks:
      return "with breaks";
    case Kind::AtRest:
      return "at rest";
    case Kind::SparseField:
      return "sparse field";
    default:
      return "long segments";
  }
}

/// A random path of about \p n points of kind \p kind; origin at (0.01, −0.02) m.
PathPoints randomPath(Kind kind, std::size_t n, std::mt19937_64& rng)
{
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  std::normal_distribution<double> gauss(0.0, 1.0);
  PathPoints path(Vector2d(0.01, -0.02));
  Vector2d p(0.01 + 0.02 * (uni(rng) - 0.5), -0.02 + 0.02 * (uni(rng) - 0.5));
  double heading = 2 * M_PI * uni(rng);
  switch (kind)
  {
    case Kind::RandomWalk:
    case Kind::WithBreaks:
      for (std::size_t i = 0; i < n; ++i)
      {
        path.add(p);
        if (kind == Kind::WithBreaks && uni(rng) < 0.05)
          path.breakPath();  // some points end up isolated (a break on both sides)
        heading += 0.4 * gauss(rng);
        const double step = 1e-5 * (0.2 + uni(rng));
        p += step * Vector2d(std::cos(heading), std::sin(heading));
      }
      break;
    case Kind::DenseZigZag:
    {
      // Sawtooth of 1–3 µm steps, a sharp turn every few samples, drifting sideways; then the
      // same trace again (exact repeats).
      std::vector<Vector2d> trace;
      for (std::size_t i = 0; i < n / 2; ++i)
      {
        trace.push_back(p);
        const double side = (i / (2 + i % 3)) % 2 ? 1.0 : -1.0;
        p += Vector2d(1e-6 * (1 + 2 * uni(rng)), side * 3e-6);
      }
      for (int pass = 0; pass < 2; ++pass)
        for (const Vector2d& q : trace)
          path.add(q);
      break;
    }
    case Kind::AtRest:
      // Dwell: ±1 nm of jitter (about one float ulp here) around one point, a short move, another
      // dwell.
      for (std::size_t i = 0; i < n; ++i)
      {
        if (i == n / 2)
          p += Vector2d(2e-5, -1e-5);
        const auto quantum = [&] { return std::clamp(std::round(0.7 * gauss(rng)), -1.0, 1.0) * 1e-9; };
        const Vector2d jitter(quantum(), quantum());
        path.add(i % 7 == 0 ? p : p + jitter);
      }
      break;
    case Kind::LongSegments:
      // Jumps across a 20 mm box (each segment crosses many cells), every tenth from a dense
      // cluster of 1 µm steps: long segments through crowded cells.
      for (std::size_t i = 0; i < n; ++i)
      {
        if (i % 10 == 0)
          path.add(Vector2d(0.01 + 0.02 * (uni(rng) - 0.5), -0.02 + 0.02 * (uni(rng) - 0.5)));
        else
          path.add(Vector2d(0.0105, -0.0195) + 1e-6 * Vector2d(gauss(rng), gauss(rng)));
      }
      break;
    case Kind::SparseField:
    {
      // Two dense clusters at opposite corners of a 350 mm field, joined by a fast jump.
      const Vector2d corners[2] = {Vector2d(-0.165, -0.17), Vector2d(0.17, 0.16)};
      for (int c = 0; c < 2; ++c)
      {
        Vector2d q = corners[c];
        for (std::size_t i = 0; i < n / 2; ++i)
        {
          path.add(q);
          heading += 0.5 * gauss(rng);
          q += 8e-6 * Vector2d(std::cos(heading), std::sin(heading));
        }
        if (c == 0)
        {
          const Vector2d to = corners[1] - q;
          const int steps = static_cast<int>(to.norm() / 1.2e-4);
          for (int k = 1; k < steps; ++k)
            path.add(q + to * (double(k) / steps));
        }
      }
      break;
    }
    default:
      break;
  }
  return path;
}

/// Query points: near the path, anywhere in its box, far away, and on stored points.
std::vector<Vector2d> queries(const PathPoints& path, std::mt19937_64& rng)
{
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  std::normal_distribution<double> gauss(0.0, 1.0);
  Vector2d lo = path.point(0), hi = path.point(0);
  for (std::size_t i = 0; i < path.size(); ++i)
  {
    lo = lo.cwiseMin(path.point(i));
    hi = hi.cwiseMax(path.point(i));
  }
  std::vector<Vector2d> q;
  const auto pick = [&] { return path.point(std::min(path.size() - 1, std::size_t(uni(rng) * path.size()))); };
  for (int k = 0; k < 120; ++k)
    q.push_back(pick() + 3e-5 * Vector2d(gauss(rng), gauss(rng)));
  for (int k = 0; k < 30; ++k)
    q.push_back(lo + (hi - lo + Vector2d(2e-4, 2e-4)).cwiseProduct(Vector2d(uni(rng), uni(rng))) -
                Vector2d(1e-4, 1e-4));
  for (int k = 0; k < 8; ++k)
  {
    const double a = 2 * M_PI * uni(rng);
    q.push_back(0.5 * (lo + hi) + (0.5 + uni(rng)) * Vector2d(std::cos(a), std::sin(a)));
  }
  for (int k = 0; k < 5; ++k)
    q.push_back(pick());
  return q;
}

/// A serpentine hatch: lines of length \p line_m along x, \p spacing_m apart, sampled every
/// \p step_m, starting at \p start, \p points samples.
void serpentine(PathPoints& path, const Vector2d& start, double line_m, double spacing_m, double step_m,
                std::size_t points)
{
  const std::size_t per_line = static_cast<std::size_t>(std::round(line_m / step_m));
  for (std::size_t k = 0; k < points; ++k)
  {
    const std::size_t line = k / (per_line + 1), along = k % (per_line + 1);
    const double x = (line % 2 ? double(per_line - along) : double(along)) * step_m;
    path.add(start + Vector2d(x, line * spacing_m));
  }
}

/// Mean and max of the segments tested per query over points near a serpentine of \p n samples.
std::pair<double, std::uint64_t> workPerQuery(const PathPoints& path, const NearestPathIndex& index, int samples,
                                              std::mt19937_64& rng)
{
  std::uniform_int_distribution<std::size_t> pick(0, path.size() - 1);
  std::normal_distribution<double> gauss(0.0, 1e-5);
  std::uint64_t total = 0, worst = 0;
  for (int k = 0; k < samples; ++k)
  {
    NearestPathWork w;
    index.distance(path.point(pick(rng)) + Vector2d(gauss(rng), gauss(rng)), std::numeric_limits<double>::infinity(),
                   &w);
    total += w.segments_tested;
    worst = std::max(worst, w.segments_tested);
  }
  return {double(total) / samples, worst};
}
}  // namespace

// Float offsets from the origin, breaks, isolated points, memory per point.
TEST(PathPoints, StoresFloatOffsetsAndBreaks)
{
  PathPoints path(Vector2d(0.1, -0.2));
  path.breakPath();  // no-op on an empty path
  EXPECT_TRUE(path.empty());
  path.add(Vector2d(0.1 + 0.3, -0.2 - 0.3));  // 0.3 m from the origin
  path.add(Vector2d(0.1, -0.2));
  path.breakPath();
  path.breakPath();  // twice = once
  path.add(Vector2d(0.2, -0.2));
  path.breakPath();
  path.add(Vector2d(0.3, -0.2));
  ASSERT_EQ(path.size(), 4u);
  EXPECT_TRUE(path.joinsNext(0));
  EXPECT_FALSE(path.joinsNext(1));
  EXPECT_FALSE(path.joinsNext(2));  // point 2 is isolated
  EXPECT_FALSE(path.joinsNext(3));  // last
  EXPECT_FALSE(path.joinsNext(99));
  // Half a float ulp at 0.3 m: 2^-26 ≈ 1.49e-8 m.
  EXPECT_LE((path.point(0) - Vector2d(0.4, -0.5)).cwiseAbs().maxCoeff(), std::ldexp(1.0, -26));
  EXPECT_EQ(path.point(1), Vector2d(0.1, -0.2));
  // The isolated point counts in the brute force.
  EXPECT_NEAR(nearestPathDistanceBruteForce(path, Vector2d(0.2, -0.19)), 0.01, 1e-9);

  PathPoints big;
  const std::size_t n = 100000;
  big.reserve(n);
  for (std::size_t i = 0; i < n; ++i)
    big.add(Vector2d(1e-6 * i, 0.0));
  EXPECT_LE(big.memoryBytes(), n * 8 + n / 8 + 256);  // 8 B/point + 1 bit/point
}

TEST(PathPoints, RejectsNonFinitePointsNamingTheIndex)
{
  PathPoints path;
  path.add(Vector2d(0, 0));
  path.add(Vector2d(1e-3, 0));
  try
  {
    path.add(Vector2d(std::nan(""), 0));
    FAIL() << "NaN accepted";
  }
  catch (const InputError& e)
  {
    EXPECT_NE(std::string(e.what()).find("actual path point 2"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("not finite"), std::string::npos) << e.what();
  }
  EXPECT_THROW(path.add(Vector2d(1e300, 0)), InputError);  // overflows the float offset
  EXPECT_EQ(path.size(), 2u);                              // nothing added
  EXPECT_THROW(PathPoints(Vector2d(0, std::numeric_limits<double>::infinity())), InputError);

  const NearestPathIndex index(path);
  EXPECT_THROW(index.distance(Vector2d(std::nan(""), 0)), InputError);
  EXPECT_THROW(index.distance(Vector2d(0, 0), -1.0), InputError);
  EXPECT_THROW(sameInstantDistance(path, 0, Vector2d(0, std::numeric_limits<double>::infinity())), InputError);
  try
  {
    sameInstantDistance(path, 2, Vector2d(0, 0));
    FAIL() << "index beyond the path accepted";
  }
  catch (const InputError& e)
  {
    EXPECT_NE(std::string(e.what()).find("sample 2"), std::string::npos) << e.what();
  }
}

// (a) and (b) against loops over all segments, seeded random paths of five kinds.
TEST(ContourError, BothDefinitionsMatchBruteForceOnRandomPaths)
{
  std::mt19937_64 rng(seed());
  std::uniform_int_distribution<std::size_t> length(2, 3000);
  for (int c = 0; c < cases(); ++c)
  {
    const Kind kind = static_cast<Kind>(c % static_cast<int>(Kind::Count));
    const PathPoints path = randomPath(kind, length(rng), rng);
    SCOPED_TRACE(std::string(kindName(kind)) + ", case " + std::to_string(c) + ", seed " + std::to_string(seed()) +
                 ", " + std::to_string(path.size()) + " points");
    const NearestPathIndex index(path);
    const auto segments = segmentsOf(path);
    for (const Vector2d& q : queries(path, rng))
    {
      const double reference = referenceNearest(segments, q);
      const double fast = index.distance(q);
      ASSERT_NEAR(fast, reference, kIndexTolerance) << "at (" << q.x() << ", " << q.y() << ")";
      EXPECT_NEAR(nearestPathDistanceBruteForce(path, q), reference, kIndexTolerance);
      // The upper bound caps the result and does not change it when above.
      EXPECT_NEAR(index.distance(q, 2 * reference + 1e-9), reference, kIndexTolerance);
      EXPECT_EQ(index.distance(q, 0.5 * reference), 0.5 * reference);
    }
    std::uniform_int_distribution<std::size_t> sample(0, path.size() - 1);
    for (int k = 0; k < 200; ++k)
    {
      const std::size_t j = sample(rng);
      const Vector2d q = path.point(sample(rng)) + Vector2d(1e-5, -2e-5);
      const double same = sameInstantDistance(path, j, q);
      ASSERT_NEAR(same, referenceSameInstant(path, j, q), kIndexTolerance) << "j = " << j;
      EXPECT_LE(index.distance(q), same + kIndexTolerance);  // (a) ≤ (b): its segments are in the path
    }
  }
}

// A dwell of 200 000 samples jittering by ±1 nm (a few float values per axis): one leaf holds a
// handful of distinct segments, so a query tests few of them.
TEST(NearestPathIndex, SpotAtRestStaysCheap)
{
  std::mt19937_64 rng(seed() + 1);
  const PathPoints path = randomPath(Kind::AtRest, 200000, rng);
  const NearestPathIndex index(path);
  EXPECT_LE(index.largestLeaf(), 64u);
  std::uint64_t worst = 0;
  for (const Vector2d& q : {Vector2d(0.0, 0.0), Vector2d(path.point(3) + Vector2d(1e-6, 0)), path.point(150000)})
  {
    NearestPathWork w;
    EXPECT_NEAR(index.distance(q, std::numeric_limits<double>::infinity(), &w), nearestPathDistanceBruteForce(path, q),
                kIndexTolerance);
    worst = std::max(worst, w.segments_tested);
  }
  EXPECT_LE(worst, 128u);
}

// Straight actual line y = 0 on dyadic points (exact in float): the distance is |offset| inside
// the span and the distance to the end beyond it.
TEST(ContourError, StraightLineOffsetClosedForm)
{
  const double step = std::ldexp(1.0, -16);  // 15.26 µm
  PathPoints path;
  for (int k = -1024; k <= 1024; ++k)
    path.add(Vector2d(k * step, 0.0));
  const NearestPathIndex index(path);
  const double end = 1024 * step;
  for (double offset : {0.0, 1e-6, -7e-6, 5e-5, 1e-3})
  {
    for (double x : {-end, -0.3 * end, 0.0, 0.123 * end, end})
    {
      const Vector2d q(x, offset);
      EXPECT_NEAR(index.distance(q), std::abs(offset), kDyadicTolerance) << x << ", " << offset;
      // (b) with the sample nearest in x: the projection falls on an adjacent segment.
      const std::size_t j = static_cast<std::size_t>(std::lround(x / step) + 1024);
      EXPECT_NEAR(sameInstantDistance(path, j, q), std::abs(offset), kDyadicTolerance);
    }
  }
  EXPECT_NEAR(index.distance(Vector2d(end + 3e-3, 4e-3)), 5e-3, kDyadicTolerance);  // 3-4-5 beyond the end
  EXPECT_NEAR(index.distance(Vector2d(-end - 6e-3, -8e-3)), 1e-2, kDyadicTolerance);
}

// Commanded 10 mm square vs actual square offset outward by d = 15 µm, sampled at other steps:
// every commanded point, corners included, is d from the actual path.
TEST(ContourError, SquareOffsetByDClosedForm)
{
  const double half = 5e-3, d = 15e-6;
  const auto square = [](double h, double step, std::vector<Vector2d>& out) {
    const Vector2d corners[5] = {{-h, -h}, {h, -h}, {h, h}, {-h, h}, {-h, -h}};
    const int per_edge = static_cast<int>(std::round(2 * h / step));
    for (int e = 0; e < 4; ++e)
      for (int k = 0; k < per_edge; ++k)
        out.push_back(corners[e] + (corners[e + 1] - corners[e]) * (double(k) / per_edge));
    out.push_back(corners[4]);
  };
  std::vector<Vector2d> commanded, actual;
  square(half, 1e-5, commanded);
  square(half + d, 1.3e-5, actual);
  PathPoints path;
  for (const Vector2d& p : actual)
    path.add(p);
  const NearestPathIndex index(path);
  ContourErrorStats stats;
  for (const Vector2d& c : commanded)
  {
    const double e = index.distance(c);
    ASSERT_NEAR(e, d, kFloatTolerance) << c.transpose();
    stats.add(e);
  }
  EXPECT_EQ(stats.count(), commanded.size());
  EXPECT_EQ(stats.countUnder(10e-6), 0u);
  EXPECT_EQ(stats.countUnder(20e-6), commanded.size());
  EXPECT_DOUBLE_EQ(stats.shareUnder(30e-6), 1.0);
  EXPECT_NEAR(stats.mean(), d, kFloatTolerance);
}

// Same instant at a corner: actual path along −x into the corner (0, 0), then along +y, sampled
// every s (dyadic, exact). With j the corner sample, a commanded point beyond the outgoing adjacent
// segment is measured to its end: e_b = √(x² + (y − s)²), while the nearest path gives e_a = x.
TEST(ContourError, SameInstantAtACornerClosedForm)
{
  const double s = std::ldexp(1.0, -16);
  PathPoints path;
  for (int k = -50; k <= 0; ++k)
    path.add(Vector2d(k * s, 0.0));
  for (int k = 1; k <= 50; ++k)
    path.add(Vector2d(0.0, k * s));
  const std::size_t corner = 50;
  ASSERT_EQ(path.point(corner), Vector2d(0, 0));
  const NearestPathIndex index(path);

  const Vector2d beyond(3e-6, s + 4e-6);
  EXPECT_NEAR(sameInstantDistance(path, corner, beyond), 5e-6, kDyadicTolerance);
  EXPECT_NEAR(index.distance(beyond), 3e-6, kDyadicTolerance);
  // Within the adjacent segments: both definitions agree.
  const Vector2d inside(2e-6, 0.5 * s);
  EXPECT_NEAR(sameInstantDistance(path, corner, inside), 2e-6, kDyadicTolerance);
  EXPECT_NEAR(index.distance(inside), 2e-6, kDyadicTolerance);
  // Outside the corner (x > 0, y < 0): both clamp to the corner point.
  const Vector2d outside(6e-6, -8e-6);
  EXPECT_NEAR(sameInstantDistance(path, corner, outside), 1e-5, kDyadicTolerance);
  EXPECT_NEAR(index.distance(outside), 1e-5, kDyadicTolerance);
  // Inside the corner on the bisector: d/√2 from each edge.
  const Vector2d bisector(-1e-6, 1e-6);
  EXPECT_NEAR(sameInstantDistance(path, corner, bisector), 1e-6, kDyadicTolerance);
}

// The delay matters for (b), not for (a): commanded = actual samples on a line; compared with the
// sample L earlier, e_b = (L − 1)·s; with the delay compensated (j = k), e_b = 0.
TEST(ContourError, SameInstantNeedsTheDelayCompensated)
{
  const double s = std::ldexp(1.0, -16);
  PathPoints path;
  for (int k = 0; k < 100; ++k)
    path.add(Vector2d(k * s, 0.0));
  const NearestPathIndex index(path);
  for (std::size_t lag : {0u, 1u, 2u, 5u})
  {
    for (std::size_t k = 10; k < 100; k += 17)
    {
      const Vector2d c = path.point(k);
      const double expected = lag <= 1 ? 0.0 : (lag - 1) * s;
      EXPECT_NEAR(sameInstantDistance(path, k - lag, c), expected, kDyadicTolerance) << "lag " << lag << ", k " << k;
      EXPECT_EQ(index.distance(c), 0.0);
    }
  }
}

// Shares, mean, max, bins and quantiles on known inputs; bin edges; rejected inputs.
TEST(ContourErrorStats, KnownInputs)
{
  ContourErrorStats stats;
  EXPECT_TRUE(std::isnan(stats.mean()));
  EXPECT_TRUE(std::isnan(stats.max()));
  EXPECT_TRUE(std::isnan(stats.shareUnder(10e-6)));
  for (double e : {0.0, 5e-6, 9.999e-6, 10e-6, 15e-6, 25e-6, 150e-6, 19.9999e-6})
    stats.add(e);
  EXPECT_EQ(stats.count(), 8u);
  EXPECT_EQ(stats.countUnder(0.0), 0u);
  EXPECT_EQ(stats.countUnder(10e-6), 3u);  // 10 µm itself is not under 10 µm
  EXPECT_EQ(stats.countUnder(20e-6), 6u);
  EXPECT_EQ(stats.countUnder(30e-6), 7u);
  EXPECT_EQ(stats.countUnder(100e-6), 7u);
  EXPECT_DOUBLE_EQ(stats.shareUnder(20e-6), 6.0 / 8.0);
  EXPECT_EQ(stats.binCount(0), 1u);
  EXPECT_EQ(stats.binCount(9), 1u);
  EXPECT_EQ(stats.binCount(10), 1u);
  EXPECT_EQ(stats.binCount(100), 1u);  // overflow
  EXPECT_EQ(stats.max(), 150e-6);
  EXPECT_NEAR(stats.mean(), (5e-6 + 9.999e-6 + 10e-6 + 15e-6 + 25e-6 + 150e-6 + 19.9999e-6) / 8, 1e-12);
  EXPECT_DOUBLE_EQ(stats.quantileUpperBound(0.5), 11e-6);  // 4th smallest, 10 µm, is in [10, 11) µm
  EXPECT_EQ(stats.quantileUpperBound(1.0), 150e-6);        // in the overflow: the max
  EXPECT_DOUBLE_EQ(stats.quantileUpperBound(0.0), 1e-6);
  ContourErrorStats narrow;  // the bin's upper edge is capped at the max
  narrow.add(10.25e-6);
  narrow.add(10.5e-6);
  EXPECT_EQ(narrow.quantileUpperBound(0.5), 10.5e-6);
  EXPECT_EQ(narrow.quantileUpperBound(1.0), 10.5e-6);

  EXPECT_THROW(stats.add(std::nan("")), NumericalError);
  EXPECT_THROW(stats.add(-1e-9), NumericalError);
  EXPECT_THROW(stats.add(2e3), NumericalError);
  EXPECT_THROW(stats.countUnder(15.5e-6), InputError);
  EXPECT_THROW(stats.countUnder(101e-6), InputError);
  EXPECT_THROW(stats.binCount(101), InputError);
  EXPECT_THROW(stats.quantileUpperBound(1.5), InputError);
  EXPECT_EQ(stats.count(), 8u);
}

// merge(a, b, c) in any order equals adding every value to one object, bit for bit.
TEST(ContourErrorStats, MergeEqualsAddingAll)
{
  std::mt19937_64 rng(seed() + 2);
  std::exponential_distribution<double> error(1.0 / 12e-6);
  ContourErrorStats all, parts[3];
  for (int k = 0; k < 30000; ++k)
  {
    const double e = error(rng);
    all.add(e);
    parts[k % 3 == 0 ? 0 : (k % 5 == 0 ? 1 : 2)].add(e);
  }
  ContourErrorStats forward, backward;
  for (int p = 0; p < 3; ++p)
    forward.merge(parts[p]);
  for (int p = 2; p >= 0; --p)
    backward.merge(parts[p]);
  EXPECT_TRUE(forward == all);
  EXPECT_TRUE(backward == all);
  EXPECT_EQ(forward.mean(), all.mean());
  EXPECT_EQ(forward.max(), all.max());
  EXPECT_EQ(forward.countUnder(20e-6), all.countUnder(20e-6));
  EXPECT_GT(all.countUnder(20e-6), 0u);
  EXPECT_LT(all.countUnder(20e-6), all.count());
  ContourErrorStats one = parts[0];
  one.add(1e-6);
  EXPECT_TRUE(one != parts[0]);
}

// Not timed: the segments tested per query near a 100 µm serpentine stay bounded as n grows
// 100-fold, on a compact hatch and on hatches scattered over a 350 mm field; memory stays O(n).
// The leaf hint: the distances of the full search bit for bit. (1) Queries in path order, each bounded, on a hatch
// whose index is refined two or three levels deep, bounds from 0 to 40 µm (most below 5 µm, as contour errors are):
// the hint spares reading cells. (2) A random walk of 5 µm steps filling a 1 mm square (refined everywhere), each
// random point queried twice, the second time bounded just above its distance so that the hint's leaf must hold the
// nearest segment: this catches a hint box clipped to its own grid's region only instead of all its ancestors' (a
// refined cell's grid reaches past its parent cell; that version gave 1–2 wrong distances in 200 000 such queries for
// most seeds, and 2 of the THESIS layer's 30.5 M).
TEST(NearestPathIndex, LeafHintGivesTheFullSearch)
{
  std::mt19937_64 rng(seed() + 17);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  std::normal_distribution<double> gauss(0.0, 3e-6);
  PathPoints path;
  serpentine(path, Vector2d(-0.0101, -0.0099), 0.0203, 1e-4, 1e-5, 600000);
  const NearestPathIndex index(path);
  ASSERT_GT(index.gridCount(), 1000u);
  NearestPathHint hint;
  NearestPathWork with, without;
  const std::size_t queries = 200000;
  for (std::size_t k = 0; k < queries; ++k)  // every sample: consecutive points share leaves
  {
    const Vector2d p = path.point(k) + Vector2d(gauss(rng), gauss(rng) + 1e-5);
    const double r = uni(rng), bound = 40e-6 * r * r * r;
    const double full = index.distance(p, bound, &without);
    ASSERT_EQ(index.distance(p, bound, &with, &hint), full) << k;
  }
  std::cout << "[hint] cells read a query " << double(with.cells_visited) / queries << " (full search "
            << double(without.cells_visited) / queries << ")\n";
  EXPECT_LT(with.cells_visited, without.cells_visited * 9 / 10);

  PathPoints walk;
  Vector2d at(0.0, 0.0);
  for (int k = 0; k < 100000; ++k)
  {
    const double a = 2 * M_PI * uni(rng);
    at = (at + 5e-6 * Vector2d(std::cos(a), std::sin(a)))
             .cwiseMax(Vector2d(-5e-4, -5e-4))
             .cwiseMin(Vector2d(5e-4, 5e-4));
    walk.add(at);
  }
  const NearestPathIndex walk_index(walk);
  NearestPathHint walk_hint;
  std::size_t hinted = 0;
  for (int q = 0; q < 400000; ++q)
  {
    const Vector2d p(5e-4 * (2 * uni(rng) - 1), 5e-4 * (2 * uni(rng) - 1));
    const double d = walk_index.distance(p, std::numeric_limits<double>::infinity(), nullptr, &walk_hint);
    NearestPathWork w;
    ASSERT_EQ(walk_index.distance(p, d * (1 + 1e-7) + 1e-13, &w, &walk_hint), d) << q;
    hinted += w.cells_visited <= 1 ? 1 : 0;
  }
  EXPECT_GT(hinted, 100000u);
}

TEST(NearestPathIndex, WorkPerQueryStaysBoundedAsPathGrows)
{
  std::mt19937_64 rng(seed() + 3);
  for (bool sparse : {false, true})
  {
    double first_mean = 0.0;
    for (std::size_t n : {10000u, 100000u, 1000000u})
    {
      PathPoints path;
      if (!sparse)
        serpentine(path, Vector2d(-0.01, -0.01), 0.005, 1e-4, 1e-5, n);
      else
        for (int c = 0; c < 4; ++c)  // four hatches at the corners of the field, joined by jumps
          serpentine(path, Vector2d(c % 2 ? 0.165 : -0.175, c / 2 ? 0.165 : -0.175), 0.005, 1e-4, 1e-5, n / 4);
      const NearestPathIndex index(path);
      const auto [mean, worst] = workPerQuery(path, index, 2000, rng);
      SCOPED_TRACE((sparse ? "sparse field, n = " : "compact hatch, n = ") + std::to_string(n));
      if (first_mean == 0.0)
        first_mean = mean;
      EXPECT_LE(worst, 100u);
      EXPECT_LE(mean, 2.0 * first_mean + 4.0);
      EXPECT_LE(index.memoryBytes(), 16 * n + 200000);
      std::cout << (sparse ? "[sparse] " : "[compact] ") << n << " points: " << mean << " segments/query (worst "
                << worst << "), " << double(index.memoryBytes()) / n << " B/point, " << index.gridCount() << " grids\n";
    }
  }
}

// The index built on two threads (its top cells refined in any order) is the one built on one: the same grids, leaves
// and memory, every query the same distance after the same work, and both equal to a loop over all segments. The path
// mixes a dense hatch, a random walk over it and a dwell, so parts are refined to different depths.
TEST(NearestPathIndex, TwoThreadsBuildTheSameIndex)
{
  std::mt19937_64 rng(seed() + 29);
  std::normal_distribution<double> gauss(0.0, 2e-5);
  PathPoints path;
  serpentine(path, Vector2d(-0.004, -0.004), 0.008, 1e-4, 1e-5, 300000);
  path.breakPath();
  Vector2d at(0.0, 0.0);
  for (int k = 0; k < 100000; ++k)
  {
    at = (at + Vector2d(gauss(rng), gauss(rng))).cwiseMax(Vector2d(-0.005, -0.005)).cwiseMin(Vector2d(0.005, 0.005));
    path.add(at);
  }
  for (int k = 0; k < 20000; ++k)
    path.add(at);
  const NearestPathIndex one(path, 1), two(path, 2);
  ASSERT_GT(one.gridCount(), 1000u);
  EXPECT_EQ(two.gridCount(), one.gridCount());
  EXPECT_EQ(two.largestLeaf(), one.largestLeaf());
  EXPECT_EQ(two.indexedSegments(), one.indexedSegments());
  EXPECT_EQ(two.memoryBytes(), one.memoryBytes());
  const auto segments = segmentsOf(path);
  std::uniform_int_distribution<std::size_t> pick(0, path.size() - 1);
  NearestPathHint hint_one, hint_two;
  for (int q = 0; q < 20000; ++q)
  {
    const Vector2d p = path.point(pick(rng)) + Vector2d(gauss(rng), gauss(rng));
    NearestPathWork work_one, work_two;
    const double d = one.distance(p, std::numeric_limits<double>::infinity(), &work_one, &hint_one);
    ASSERT_EQ(two.distance(p, std::numeric_limits<double>::infinity(), &work_two, &hint_two), d) << q;
    ASSERT_EQ(work_two.cells_visited, work_one.cells_visited) << q;
    ASSERT_EQ(work_two.segments_tested, work_one.segments_tested) << q;
    if (q % 100 == 0)
    {
      ASSERT_NEAR(d, referenceNearest(segments, p), kIndexTolerance) << q;
    }
  }
}
