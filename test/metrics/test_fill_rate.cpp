/// \file test_fill_rate.cpp
/// \brief Fill-rate grid: closed forms on straight lines (cell counts worked out by hand), a
/// serpentine fill, sub-stepping, bounds, bad input, and seeded random paths against an independent
/// brute-force computation (every cell against every segment, by a different geometric test).
///
/// Geometry of the hand counts: d = 70 µm, w = d/2, grid origin (0, 0); a coordinate written
/// "a.b" below is (a.b)·d. A horizontal line at y = 50.6 reaches row 50 (it lies in it) and row 51
/// (its bottom edge 51 is 0.4 away < 0.5) but not row 49 (top edge 50 is 0.6 away). From x = 10.2 to
/// 60.8 it reaches columns 9..61: column 9 (right edge 10 is 0.2 from the end) also in row 51 (corner
/// (10, 51) is √(0.2² + 0.4²) = 0.447 away), column 8 not (1.2 away), likewise on the right.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <random>
#include <stdexcept>
#include <vector>

#include "scanhead/common/errors.hpp"
#include "scanhead/metrics/fill_rate.hpp"

using Eigen::Vector2d;
using scanhead::FillRateGrid;

namespace
{
constexpr double kD = 70e-6;  // spot diameter = cell pitch [m]

Vector2d cells(double cx, double cy)
{
  return Vector2d(cx * kD, cy * kD);
}

FillRateGrid grid100()
{
  return FillRateGrid(Vector2d(0.0, 0.0), Vector2d(100 * kD, 100 * kD), kD);
}

void commandedLine(FillRateGrid& g, double x0, double x1, double y)
{
  g.addCommanded(cells(x0, y), true);
  g.addCommanded(cells(x1, y), true);
  g.breakCommanded();
}

void actualLine(FillRateGrid& g, double x0, double x1, double y)
{
  g.addActual(cells(x0, y), true);
  g.addActual(cells(x1, y), true);
  g.breakActual();
}

std::uint64_t countState(const FillRateGrid& g, std::uint8_t mask, std::uint8_t value)
{
  std::uint64_t n = 0;
  for (int r = 0; r < g.height(); ++r)
    for (int c = 0; c < g.width(); ++c)
      n += (g.cellState(c, r) & mask) == value;
  return n;
}
}  // namespace

TEST(FillRate, GridSize)
{
  const FillRateGrid g = grid100();
  EXPECT_EQ(g.width(), 100);  // 7 mm / 70 µm is 100.00000000000001: the tolerance keeps it at 100
  EXPECT_EQ(g.height(), 100);
  EXPECT_EQ(g.pitch(), kD);
  EXPECT_EQ(g.cellsToFill(), 0u);
  EXPECT_TRUE(std::isnan(g.fillRate())) << "nothing to fill";
  const FillRateGrid odd(Vector2d(-1e-3, 2e-3), Vector2d(-1e-3 + 10.5 * kD, 2e-3), kD);
  EXPECT_EQ(odd.width(), 11);
  EXPECT_EQ(odd.height(), 1);
}

TEST(FillRate, SameLineIsFull)
{
  FillRateGrid g = grid100();
  commandedLine(g, 10.2, 60.8, 50.6);
  actualLine(g, 10.2, 60.8, 50.6);
  EXPECT_EQ(g.cellsToFill(), 2u * 53u);  // rows 50, 51 × columns 9..61
  EXPECT_EQ(g.cellsReached(), 106u);
  EXPECT_EQ(g.cellsReachedOutside(), 0u);
  EXPECT_EQ(g.fillRate(), 1.0);
  EXPECT_EQ(g.pointsOutside(), 0u);
  for (int r = 48; r <= 53; ++r)
    for (int c = 7; c <= 63; ++c)
    {
      const bool in = (r == 50 || r == 51) && c >= 9 && c <= 61;
      EXPECT_EQ(g.cellState(c, r), in ? 3 : 0) << c << ", " << r;
    }
}

TEST(FillRate, OffsetLosesOneRow)
{
  for (double offset : {1.0, -1.0})
  {
    FillRateGrid g = grid100();
    commandedLine(g, 10.2, 60.8, 50.6);
    actualLine(g, 10.2, 60.8, 50.6 + offset);  // rows 51, 52 (or 49, 50): one of the two rows kept
    EXPECT_EQ(g.cellsReached(), 53u);
    EXPECT_EQ(g.cellsReachedOutside(), 53u);
    EXPECT_EQ(g.fillRate(), 0.5);
  }
  // Three lines one cell apart fill rows 50..53 (212 cells); the same three one cell higher reach
  // rows 51..54: row 50 is lost, 3/4 kept.
  FillRateGrid g = grid100();
  for (double y : {50.6, 51.6, 52.6})
  {
    commandedLine(g, 10.2, 60.8, y);
    actualLine(g, 10.2, 60.8, y + 1.0);
  }
  EXPECT_EQ(g.cellsToFill(), 4u * 53u);
  EXPECT_EQ(g.cellsReached(), 3u * 53u);
  EXPECT_EQ(g.cellsReachedOutside(), 53u);
  EXPECT_EQ(g.fillRate(), 0.75);
  // A shorter actual line loses columns: x from 20.2 to 60.8 reaches columns 19..61 (43 of 53).
  FillRateGrid s = grid100();
  commandedLine(s, 10.2, 60.8, 50.6);
  actualLine(s, 20.2, 60.8, 50.6);
  EXPECT_EQ(s.cellsReached(), 2u * 43u);
  EXPECT_DOUBLE_EQ(s.fillRate(), 43.0 / 53.0);
}

// A cell is within w of two lines only if they are less than d + 2w = 2d apart: any offset ≥ 2d
// gives 0 %, whatever the alignment. (An offset of d + w is not enough: at y = 50.6 + 1.5 = 52.1 the
// actual line still reaches row 51, whose top edge is 0.1 away.)
TEST(FillRate, OffsetBeyondTwoDiametersIsEmpty)
{
  for (double offset : {2.0, 2.05, 2.3, 2.5, 2.99, -2.0, -2.41})
  {
    FillRateGrid g = grid100();
    commandedLine(g, 10.2, 60.8, 50.6);
    actualLine(g, 10.2, 60.8, 50.6 + offset);
    EXPECT_EQ(g.cellsReached(), 0u) << offset;
    EXPECT_EQ(g.cellsReachedOutside(), 106u) << offset;
    EXPECT_EQ(g.fillRate(), 0.0) << offset;
  }
  FillRateGrid g = grid100();
  commandedLine(g, 10.2, 60.8, 50.6);
  actualLine(g, 10.2, 60.8, 52.1);  // offset d + w
  EXPECT_EQ(g.cellsReached(), 53u);
}

// Edge probes of the strict "distance < w": a point centred in a cell reaches only that cell; at
// 0.4999 of a cell from the centre it reaches the neighbour too.
TEST(FillRate, CellBorderProbes)
{
  FillRateGrid g = grid100();
  g.addActual(cells(20.5, 30.5), true);
  EXPECT_EQ(g.cellsReachedOutside(), 1u);
  EXPECT_EQ(g.cellState(20, 30), FillRateGrid::kReached);
  g.addActual(cells(40.5, 30.9999), true);  // joined to the first point: one more row along y ≈ 30.75
  g.breakActual();
  FillRateGrid p = grid100();
  p.addActual(cells(40.5, 30.9999), true);
  EXPECT_EQ(p.cellsReachedOutside(), 2u);  // (40, 30) and (40, 31), whose edge is 1e-4 away
  EXPECT_EQ(p.cellState(40, 31), FillRateGrid::kReached);
  EXPECT_EQ(p.cellState(40, 29), 0);
  EXPECT_EQ(p.cellState(41, 31), 0);  // corner (41, 31) is 0.5 away: not < w
}

TEST(FillRate, BreaksAndLaserOffDoNotJoin)
{
  FillRateGrid g = grid100();
  g.addCommanded(cells(10.5, 10.5), true);
  g.breakCommanded();
  g.addCommanded(cells(30.5, 10.5), true);
  EXPECT_EQ(g.cellsToFill(), 2u);
  g.addCommanded(cells(50.5, 10.5), false);  // laser off at the end: the segment to it does not mark
  EXPECT_EQ(g.cellsToFill(), 2u);
  g.addCommanded(cells(70.5, 10.5), true);  // laser back on: the segment from the off point does not mark
  EXPECT_EQ(g.cellsToFill(), 3u);
  g.addCommanded(cells(72.5, 10.5), true);  // joined: columns 70..72
  EXPECT_EQ(g.cellsToFill(), 5u);
  g.addActual(cells(30.5, 10.5), false);  // a laser-off point reaches nothing
  EXPECT_EQ(g.cellsReached() + g.cellsReachedOutside(), 0u);
}

// The actual spot sweeps a 3 mm square along a serpentine of spacing ≤ 0.9 d given only by its
// vertices (long segments): every cell meeting the open square is reached. With a spacing of 3.1 d
// (gaps of 2.1 d between the swept bands) whole rows inside are missed.
TEST(FillRate, SerpentineFillsEveryInteriorCell)
{
  const double side = 3e-3;
  const Vector2d lo(-0.5e-3, -0.5e-3), hi(3.5e-3, 3.5e-3);
  for (double spacing_cells : {0.9, 3.1})
  {
    FillRateGrid g(lo, hi, kD);
    const int lines = static_cast<int>(std::ceil(side / (spacing_cells * kD)));
    for (int k = 0; k <= lines; ++k)
    {
      const double y = side * k / lines;
      const double x_from = k % 2 == 0 ? 0.0 : side;
      g.addActual(Vector2d(x_from, y), true);
      g.addActual(Vector2d(side - x_from, y), true);
    }
    std::uint64_t interior = 0, missed = 0;
    for (int r = 0; r < g.height(); ++r)
      for (int c = 0; c < g.width(); ++c)
      {
        const double x0 = lo.x() + c * kD, y0 = lo.y() + r * kD;
        if (x0 + kD <= 0.0 || x0 >= side || y0 + kD <= 0.0 || y0 >= side)
          continue;  // does not meet the open square
        ++interior;
        missed += (g.cellState(c, r) & FillRateGrid::kReached) == 0;
      }
    EXPECT_GT(interior, 1800u);
    if (spacing_cells < 1.0)
      EXPECT_EQ(missed, 0u);
    else
      EXPECT_GT(missed, interior / 5) << "bands of 2.1 d between the lines hold whole unreached rows";
    EXPECT_EQ(g.pointsOutside(), 0u);
  }
}

// A spot moving 5 mm between two samples reaches exactly the cells of the same line sampled every
// 0.1 µm, in any direction.
TEST(FillRate, SubSteppingLeavesNoHole)
{
  const Vector2d a = cells(3.37, 7.91), b = cells(88.2, 61.05);
  FillRateGrid sparse = grid100(), dense = grid100();
  sparse.addActual(a, true);
  sparse.addActual(b, true);
  const int n = static_cast<int>((b - a).norm() / 0.1e-6);
  for (int k = 0; k <= n; ++k)
    dense.addActual(a + (b - a) * (static_cast<double>(k) / n), true);
  EXPECT_EQ(sparse.cellsReachedOutside(), dense.cellsReachedOutside());
  for (int r = 0; r < 100; ++r)
    for (int c = 0; c < 100; ++c)
      ASSERT_EQ(sparse.cellState(c, r), dense.cellState(c, r)) << c << ", " << r;
  // A horizontal line crossing the whole grid in one step (from -1 m to 1 m): every cell of rows 50, 51.
  FillRateGrid g = grid100();
  g.addActual(Vector2d(-1.0, 50.6 * kD), true);
  g.addActual(Vector2d(1.0, 50.6 * kD), true);
  EXPECT_EQ(g.cellsReachedOutside(), 200u);
  EXPECT_EQ(g.actualPointsOutside(), 2u);
}

TEST(FillRate, PointsOutsideAreCounted)
{
  FillRateGrid g = grid100();
  // From inside across the right edge (x = 100): the end point's disc is beyond, the cells inside
  // are still marked.
  g.addCommanded(cells(90.2, 50.6), true);
  g.addCommanded(cells(120.0, 50.6), true);
  EXPECT_EQ(g.commandedPointsOutside(), 1u);
  EXPECT_EQ(g.cellsToFill(), 2u * 11u);     // columns 89..99 of rows 50, 51
  g.addCommanded(cells(99.6, 20.5), true);  // inside, but its disc crosses the edge (0.4 < 0.5)
  EXPECT_EQ(g.commandedPointsOutside(), 2u);
  g.addCommanded(cells(99.4, 20.5), false);    // laser off: not counted
  g.addActual(Vector2d(1e300, 0.0), true);     // absurd but finite: counted, reaches nothing
  g.addActual(Vector2d(-1.7e308, 0.0), true);  // its cell coordinate overflows: counted, not joined
  g.addActual(cells(50.5, 50.5), true);
  EXPECT_EQ(g.actualPointsOutside(), 2u);
  EXPECT_EQ(g.pointsOutside(), 4u);
  EXPECT_EQ(g.cellsReachedOutside(), 1u) << "only the cell of the last point, not joined to the overflowed one";
  // Points on the edge cells whose discs stay inside are not counted.
  FillRateGrid e = grid100();
  e.addActual(cells(0.5, 0.5), true);
  e.addActual(cells(99.5, 99.5), true);
  EXPECT_EQ(e.pointsOutside(), 0u);
}

TEST(FillRate, BadInputAndLimits)
{
  EXPECT_THROW(FillRateGrid(Vector2d(0, 0), Vector2d(1e-3, 1e-3), 0.0), scanhead::ConfigError);
  EXPECT_THROW(FillRateGrid(Vector2d(0, 0), Vector2d(1e-3, 1e-3), -70e-6), scanhead::ConfigError);
  EXPECT_THROW(FillRateGrid(Vector2d(0, 0), Vector2d(1e-3, 1e-3), NAN), scanhead::ConfigError);
  EXPECT_THROW(FillRateGrid(Vector2d(0, 0), Vector2d(1e-3, 1e-3), INFINITY), scanhead::ConfigError);
  EXPECT_THROW(FillRateGrid(Vector2d(0, 0), Vector2d(10.0, 10.0), 70e-6), scanhead::ConfigError) << "2e10 cells";
  EXPECT_THROW(FillRateGrid(Vector2d(0, 0), Vector2d(1e6, 0.0), 1e-6), scanhead::ConfigError) << "side > 2^31-1";
  EXPECT_THROW(FillRateGrid(Vector2d(0, NAN), Vector2d(1e-3, 1e-3), kD), scanhead::InputError);
  EXPECT_THROW(FillRateGrid(Vector2d(0, 0), Vector2d(-1e-3, 1e-3), kD), scanhead::InputError);
  try
  {
    FillRateGrid(Vector2d(0, 0), Vector2d(1e-3, 1e-3), -7e-5);
    FAIL();
  }
  catch (const scanhead::ConfigError& e)
  {
    EXPECT_NE(std::string(e.what()).find("spot diameter"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("-6.9999999999999994e-05 m"), std::string::npos) << e.what();
  }

  FillRateGrid g = grid100();
  g.addCommanded(cells(10.5, 10.5), true);
  EXPECT_THROW(g.addCommanded(Vector2d(NAN, 0.0), true), scanhead::InputError);
  EXPECT_THROW(g.addActual(Vector2d(0.0, INFINITY), false), scanhead::InputError);
  g.addCommanded(cells(12.5, 10.5), true);  // still joined to the last good point
  EXPECT_EQ(g.cellsToFill(), 3u);
  EXPECT_THROW(g.cellState(100, 0), std::out_of_range);
  EXPECT_THROW(g.cellState(0, -1), std::out_of_range);
  g.reset();
  EXPECT_EQ(g.cellsToFill(), 0u);
  EXPECT_EQ(countState(g, 3, 0), 10000u);
  g.addCommanded(cells(40.5, 40.5), true);  // not joined to the point before the reset
  EXPECT_EQ(g.cellsToFill(), 1u);
}

// The THESIS field: 350 mm at 70 µm is 5000 × 5000 = 25 M cells in 2 bits each (6.25 MB).
TEST(FillRate, MemoryIsTwoBitsPerCell)
{
  const FillRateGrid g(Vector2d(-0.175, -0.175), Vector2d(0.175, 0.175), kD);
  EXPECT_EQ(g.width(), 5000);
  EXPECT_EQ(g.height(), 5000);
  EXPECT_GE(g.memoryBytes(), 6250000u);
  EXPECT_LT(g.memoryBytes(), 6251000u);
}

// ---------------------------------------------------------------------------------------------
// Brute force: the set of cells within w of each laser-on path, computed cell by cell against every
// segment by a different test (the segment meets the square dilated by the disc: one of the two
// crossed rectangles, or a corner disc), and the points-outside count from the point positions.

namespace
{
struct Event
{
  bool actual;
  bool is_break;
  Vector2d p;
  bool on;
};

/// \brief Segment a-b meets the closed axis-aligned rectangle: bounding boxes overlap and the corners
/// are not all strictly on one side of the line (separating axis test).
bool segmentMeetsRect(const Vector2d& a, const Vector2d& b, double x0, double y0, double x1, double y1)
{
  if (std::max(a.x(), b.x()) < x0 || std::min(a.x(), b.x()) > x1 || std::max(a.y(), b.y()) < y0 ||
      std::min(a.y(), b.y()) > y1)
    return false;
  const Vector2d d = b - a;
  int positive = 0, negative = 0;
  for (const Vector2d& c : {Vector2d(x0, y0), Vector2d(x1, y0), Vector2d(x0, y1), Vector2d(x1, y1)})
  {
    const double side = d.x() * (c.y() - a.y()) - d.y() * (c.x() - a.x());
    positive += side > 0.0;
    negative += side < 0.0;
  }
  return positive < 4 && negative < 4;
}

double distanceToSegment(const Vector2d& p, const Vector2d& a, const Vector2d& b)
{
  const Vector2d d = b - a;
  const double t = d.squaredNorm() > 0.0 ? std::min(1.0, std::max(0.0, (p - a).dot(d) / d.squaredNorm())) : 0.0;
  return (a + t * d - p).norm();
}

bool reaches(const Vector2d& a, const Vector2d& b, double x0, double y0, double d)
{
  const double w = d / 2, x1 = x0 + d, y1 = y0 + d;
  if (segmentMeetsRect(a, b, x0 - w, y0, x1 + w, y1) || segmentMeetsRect(a, b, x0, y0 - w, x1, y1 + w))
    return true;
  for (const Vector2d& c : {Vector2d(x0, y0), Vector2d(x1, y0), Vector2d(x0, y1), Vector2d(x1, y1)})
    if (distanceToSegment(c, a, b) < w)
      return true;
  return false;
}

std::vector<Event> randomPaths(std::mt19937& rng, const Vector2d& lo, const Vector2d& hi, int points)
{
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  std::vector<Event> events;
  const Vector2d margin(3 * kD, 3 * kD);
  const Vector2d span = hi - lo + 2 * margin;
  Vector2d c = lo + 0.5 * (hi - lo);
  for (int k = 0; k < points; ++k)
  {
    if (uni(rng) < 0.05)
      c = lo - margin + Vector2d(uni(rng) * span.x(), uni(rng) * span.y());  // jump anywhere (also outside)
    else
    {
      const double step = (uni(rng) < 0.1 ? 25.0 : 2.0) * kD * uni(rng);
      const double angle = 2 * M_PI * uni(rng);
      c += step * Vector2d(std::cos(angle), std::sin(angle));
    }
    if (uni(rng) < 0.03)
      events.push_back({false, true, Vector2d::Zero(), false});
    events.push_back({false, false, c, uni(rng) < 0.8});
    // The actual spot: the commanded point plus up to ±1.5 d of error, its own laser state and breaks.
    if (uni(rng) < 0.03)
      events.push_back({true, true, Vector2d::Zero(), false});
    const Vector2d error = (Vector2d(uni(rng), uni(rng)) - Vector2d(0.5, 0.5)) * 3 * kD;
    events.push_back({true, false, c + error, uni(rng) < 0.8});
  }
  return events;
}

void feed(FillRateGrid& g, const std::vector<Event>& events, bool actual_only, bool commanded_only)
{
  for (const Event& e : events)
  {
    if ((e.actual && commanded_only) || (!e.actual && actual_only))
      continue;
    if (e.is_break)
      e.actual ? g.breakActual() : g.breakCommanded();
    else
      e.actual ? g.addActual(e.p, e.on) : g.addCommanded(e.p, e.on);
  }
}
}  // namespace

TEST(FillRate, RandomPathsMatchBruteForce)
{
  const Vector2d lo(-0.35e-3, 0.2e-3);
  const Vector2d hi = lo + Vector2d(40.3 * kD, 29.7 * kD);  // 41 × 30 cells
  for (unsigned seed = 1; seed <= 8; ++seed)
  {
    std::mt19937 rng(seed);  // fixed seeds
    const std::vector<Event> events = randomPaths(rng, lo, hi, 150);

    // Reference: segments and points of each path by the joining rule, then every cell.
    const int width = 41, height = 30;
    std::vector<std::uint8_t> state(width * height, 0);
    std::uint64_t outside[2] = {0, 0};
    for (int path = 0; path < 2; ++path)
    {
      bool have = false, last_on = false;
      Vector2d last;
      std::vector<std::pair<Vector2d, Vector2d>> pieces;
      for (const Event& e : events)
      {
        if (e.actual != (path == 1))
          continue;
        if (e.is_break)
        {
          have = false;
          continue;
        }
        if (e.on)
        {
          pieces.emplace_back(have && last_on ? last : e.p, e.p);
          const Vector2d q = e.p - lo;
          if (q.x() < kD / 2 || q.y() < kD / 2 || width * kD - q.x() < kD / 2 || height * kD - q.y() < kD / 2)
            ++outside[path];
        }
        have = true;
        last_on = e.on;
        last = e.p;
      }
      for (int r = 0; r < height; ++r)
        for (int c = 0; c < width; ++c)
          for (const auto& piece : pieces)
            if (reaches(piece.first, piece.second, lo.x() + c * kD, lo.y() + r * kD, kD))
            {
              state[r * width + c] |= path == 0 ? 1 : 2;
              break;
            }
    }
    std::uint64_t to_fill = 0, reached = 0, beside = 0;
    for (std::uint8_t s : state)
    {
      to_fill += s & 1;
      reached += s == 3;
      beside += s == 2;
    }
    ASSERT_GT(to_fill, 100u) << "seed " << seed;
    ASSERT_GT(reached, 50u) << "seed " << seed;
    ASSERT_GT(beside, 10u) << "seed " << seed;

    FillRateGrid interleaved(lo, hi, kD), in_turn(lo, hi, kD);
    ASSERT_EQ(interleaved.width(), width);
    ASSERT_EQ(interleaved.height(), height);
    feed(interleaved, events, false, false);
    feed(in_turn, events, true, false);  // actual first, then commanded: counts kept right either way
    feed(in_turn, events, false, true);
    for (const FillRateGrid* g : {&interleaved, &in_turn})
    {
      for (int r = 0; r < height; ++r)
        for (int c = 0; c < width; ++c)
          ASSERT_EQ(g->cellState(c, r), state[r * width + c]) << "seed " << seed << " cell " << c << ", " << r;
      EXPECT_EQ(g->cellsToFill(), to_fill);
      EXPECT_EQ(g->cellsReached(), reached);
      EXPECT_EQ(g->cellsReachedOutside(), beside);
      EXPECT_EQ(g->fillRate(), static_cast<double>(reached) / static_cast<double>(to_fill));
      EXPECT_EQ(g->commandedPointsOutside(), outside[0]);
      EXPECT_EQ(g->actualPointsOutside(), outside[1]);
    }
  }
}
