// Scan-path generators: measured on the output (spacing, angle, island size, offsets, structure,
// containment), not taken from the parameters.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <set>

#include "scanhead/common/errors.hpp"
#include "scanhead/job/formats/job_io.hpp"
#include "scanhead/job/generators/scan_generators.hpp"

using namespace scanhead;
using Eigen::Vector2d;

namespace
{
const std::string kData = std::string(SCANHEAD_SOURCE_DIR) + "/test/data/";
constexpr double kInside = 1e-12;  // m: clipped points lie on edges up to rounding of mm coordinates
constexpr double kSpacing = 1e-9;  // m: the brief's tolerance on measured hatch spacing
constexpr double kAngle = 1e-9;    // rad: on measured hatch angle

HatchStyle style(double spacing_m, double angle_rad, bool meander)
{
  HatchStyle s;
  s.spacing_m = spacing_m;
  s.angle_rad = angle_rad;
  s.meander = meander;
  s.mark_speed_mps = 1.2;
  s.jump_speed_mps = 5.0;
  s.power_w = 180.0;
  return s;
}

std::vector<const Polyline*> marks(const Job& job)
{
  std::vector<const Polyline*> out;
  for (const Polyline& p : job.polylines)
    if (p.type == PolylineType::Mark)
      out.push_back(&p);
  return out;
}

double length(const Polyline& p)
{
  double sum = 0.0;
  for (std::size_t k = 1; k < p.points.size(); ++k)
    sum += (p.points[k] - p.points[k - 1]).norm();
  return sum;
}

/// Recipe and MARK/JUMP structure common to every generator, and every point inside the shape.
void expectWellFormed(const Job& job, const Shape& shape, const HatchStyle& s)
{
  ASSERT_FALSE(job.polylines.empty());
  EXPECT_EQ(job.polylines.front().type, PolylineType::Mark);
  for (std::size_t i = 0; i < job.polylines.size(); ++i)
  {
    const Polyline& p = job.polylines[i];
    ASSERT_GE(p.points.size(), 2u);
    if (p.type == PolylineType::Mark)
    {
      EXPECT_EQ(p.speed_mps, s.mark_speed_mps);
      EXPECT_EQ(p.power_w, s.power_w);
    }
    else
    {
      EXPECT_EQ(p.speed_mps, s.jump_speed_mps);
      EXPECT_EQ(p.power_w, 0.0);
      EXPECT_EQ(p.points.size(), 2u);
      EXPECT_NE(p.points.front(), p.points.back());
      ASSERT_LT(i + 1, job.polylines.size()) << "a job does not end with a jump";
      EXPECT_EQ(job.polylines[i + 1].type, PolylineType::Mark);
    }
    // Continuity: each polyline starts where the previous ended (the jumps are explicit).
    if (i > 0)
    {
      EXPECT_EQ(p.points.front(), job.polylines[i - 1].points.back()) << "polyline " << i;
    }
    if (p.type == PolylineType::Mark)
    {
      for (const Vector2d& q : p.points)
        ASSERT_LE(distanceOutside(shape, q), kInside) << job.name << " polyline " << i << " (" << q.transpose() << ")";
    }
  }
}

/// Offset s = p·n of every straight mark, sorted and merged within 1e-12 m (pieces of one line).
std::vector<double> lineOffsets(const Job& job, double angle_rad)
{
  const Vector2d n(-std::sin(angle_rad), std::cos(angle_rad));
  std::vector<double> s;
  for (const Polyline* m : marks(job))
    s.push_back(m->points.front().dot(n));
  std::sort(s.begin(), s.end());
  std::vector<double> out;
  for (double v : s)
    if (out.empty() || v - out.back() > 1e-12)
      out.push_back(v);
  return out;
}

/// Angle difference folded to [0, π/2] (line orientation, direction ignored).
double lineAngleError(const Vector2d& direction, double angle_rad)
{
  double e = std::fmod(std::fabs(std::atan2(direction.y(), direction.x()) - angle_rad), M_PI);
  return std::min(e, M_PI - e);
}

std::vector<Shape> testShapes()
{
  return {makeRectangle(0.010, 0.010), makeCircle(Vector2d(0.001, -0.002), 0.005, 1e-6),
          readPolygonFile(kData + "polygon_l_shape.txt"), readPolygonFile(kData + "polygon_holes_full.txt")};
}
}  // namespace

TEST(ScanGenerators, HatchSpacingAndAngleMeasuredOnTheOutput)
{
  for (const Shape& shape : testShapes())
    for (const double angle : {0.0, 0.3, M_PI / 4.0, 1.2, M_PI / 2.0, 2.9})
    {
      const HatchStyle s = style(100e-6, angle, true);
      const Job job = hatch(shape, s);
      expectWellFormed(job, shape, s);
      for (const Polyline* m : marks(job))
      {
        ASSERT_EQ(m->points.size(), 2u);
        ASSERT_LT(lineAngleError(m->points.back() - m->points.front(), angle), kAngle) << shape.name;
      }
      const std::vector<double> offsets = lineOffsets(job, angle);
      ASSERT_GT(offsets.size(), 40u);
      for (std::size_t k = 1; k < offsets.size(); ++k)
        ASSERT_NEAR(offsets[k] - offsets[k - 1], 100e-6, kSpacing) << shape.name << " angle " << angle;
    }
  // 10 mm at 100 µm: 100 lines, the outer ones 50 µm from the edges.
  const std::vector<double> y = lineOffsets(hatch(makeRectangle(0.010, 0.010), style(100e-6, 0.0, true)), 0.0);
  ASSERT_EQ(y.size(), 100u);
  EXPECT_NEAR(y.front(), -0.00495, 1e-15);
  EXPECT_NEAR(y.back(), 0.00495, 1e-15);
}

TEST(ScanGenerators, MeanderAlternatesAndRasterDoesNot)
{
  const Shape square = makeRectangle(0.010, 0.010);
  const double angle = 0.4;
  const Vector2d d(std::cos(angle), std::sin(angle));
  for (const bool meander : {true, false})
  {
    const HatchStyle s = style(200e-6, angle, meander);
    const Job job = hatch(square, s);
    expectWellFormed(job, square, s);
    const auto m = marks(job);
    ASSERT_GT(m.size(), 60u);
    for (std::size_t k = 0; k < m.size(); ++k)
    {
      const double along = (m[k]->points.back() - m[k]->points.front()).normalized().dot(d);
      const double expected = (meander && k % 2 == 1) ? -1.0 : 1.0;
      ASSERT_NEAR(along, expected, 1e-12) << (meander ? "meander" : "raster") << " mark " << k;
    }
    // One jump between consecutive lines; meander jumps are short (near one spacing at the corners
    // of the rotated square), raster jumps go back across the square.
    EXPECT_EQ(job.polylines.size(), 2 * m.size() - 1);
    double longest_jump = 0.0;
    for (const Polyline& p : job.polylines)
      if (p.type == PolylineType::Jump)
        longest_jump = std::max(longest_jump, length(p));
    // Meander: consecutive ends slide along one edge (h / cos θ or h / sin θ apart), or straddle a
    // corner (less than the sum); measured 0.51 mm here.
    if (meander)
      EXPECT_LT(longest_jump, 200e-6 / std::sin(angle) + 200e-6 / std::cos(angle));
    else
      EXPECT_GT(longest_jump, 0.010);
  }
  // Axis-aligned meander: each jump is exactly one spacing.
  const Job axis = hatch(square, style(100e-6, 0.0, true));
  for (const Polyline& p : axis.polylines)
  {
    if (p.type == PolylineType::Jump)
    {
      ASSERT_NEAR(length(p), 100e-6, kSpacing);
    }
  }
}

TEST(ScanGenerators, ConcaveLineGivesOnePieceEachInScanDirection)
{
  const Shape l = readPolygonFile(kData + "polygon_l_shape.txt");
  // Vertical lines (90°) cross the L's bottom arm only beyond x = 4 mm, both arms before it.
  const Job job = hatch(l, style(100e-6, M_PI / 2.0, true));
  expectWellFormed(job, l, style(100e-6, M_PI / 2.0, true));
  std::map<long, int> pieces_per_line;
  for (const Polyline* m : marks(job))
    ++pieces_per_line[std::lround(m->points.front().x() * 1e7)];
  EXPECT_EQ(pieces_per_line.size(), 100u);
  for (const auto& [x, count] : pieces_per_line)
    EXPECT_EQ(count, 1) << x;  // the L's lines are never cut in two…
  const Shape holes = readPolygonFile(kData + "polygon_holes_full.txt");
  int cut_lines = 0;
  std::map<long, int> holed;
  const Job holed_job = hatch(holes, style(100e-6, 0.0, true));
  for (const Polyline* m : marks(holed_job))
    ++holed[std::lround(m->points.front().y() * 1e7)];
  for (const auto& [y, count] : holed)
    cut_lines += count == 2;
  EXPECT_EQ(cut_lines, 40);  // …but the lines through the 4 mm hole are
}

TEST(ScanGenerators, StripesPartitionTheHatch)
{
  for (const Shape& shape : testShapes())
  {
    const double width = 0.003;
    const HatchStyle s = style(100e-6, 0.7, true);
    const Job job = stripes(shape, s, width);
    expectWellFormed(job, shape, s);
    const Vector2d d(std::cos(0.7), std::sin(0.7));
    double total = 0.0;
    long stripe_index = -1;
    double u_min = 1e9;
    for (const Ring& r : shape.rings)
      for (const Vector2d& p : r)
        u_min = std::min(u_min, p.dot(d));
    for (const Polyline* m : marks(job))
    {
      const double len = length(*m);
      total += len;
      ASSERT_LE(len, width + 1e-12);
      ASSERT_LT(lineAngleError(m->points.back() - m->points.front(), 0.7), kAngle);
      // Stripe of the mark from its midpoint along d: never goes back to an earlier stripe.
      const double u = 0.5 * (m->points.front() + m->points.back()).dot(d);
      const long index = static_cast<long>(std::floor((u - u_min) / width));
      ASSERT_GE(index, stripe_index);
      stripe_index = index;
    }
    double hatch_total = 0.0;
    const Job plain = hatch(shape, s);
    for (const Polyline* m : marks(plain))
      hatch_total += length(*m);
    EXPECT_NEAR(total, hatch_total, 1e-12 * hatch_total) << shape.name;  // same lines, only cut
  }
}

TEST(ScanGenerators, ChessboardIslandSizeAndAlternation)
{
  const Shape square = makeRectangle(0.010, 0.010, Vector2d(0.002, 0.001));
  const double island = 0.0025;
  const HatchStyle s = style(100e-6, 0.0, true);
  const Job job = chessboard(square, s, island);
  expectWellFormed(job, square, s);
  // Group the marks by island (from their midpoints) in output order.
  struct Island
  {
    Vector2d lo = Vector2d::Constant(1e9), hi = Vector2d::Constant(-1e9);
    std::set<int> orientations;  // 0: along x, 1: along y
    int marks = 0;
  };
  std::map<std::pair<long, long>, Island> islands;
  std::vector<std::pair<long, long>> order;
  const Vector2d origin(-0.003, -0.004);
  for (const Polyline* m : marks(job))
  {
    const Vector2d mid = 0.5 * (m->points.front() + m->points.back());
    const std::pair<long, long> key{static_cast<long>(std::floor((mid.y() - origin.y()) / island)),
                                    static_cast<long>(std::floor((mid.x() - origin.x()) / island))};
    if (order.empty() || order.back() != key)
    {
      ASSERT_TRUE(order.empty() || order.back() < key) << "islands row by row, left to right, each once";
      order.push_back(key);
    }
    Island& is = islands[key];
    for (const Vector2d& p : m->points)
    {
      is.lo = is.lo.cwiseMin(p);
      is.hi = is.hi.cwiseMax(p);
    }
    const Vector2d dir = m->points.back() - m->points.front();
    is.orientations.insert(std::fabs(dir.x()) > std::fabs(dir.y()) ? 0 : 1);
    ASSERT_LT(std::min(std::fabs(dir.x()), std::fabs(dir.y())), kAngle * dir.norm());  // axis-aligned
    ++is.marks;
  }
  ASSERT_EQ(islands.size(), 16u);
  for (const auto& [key, is] : islands)
  {
    ASSERT_EQ(is.orientations.size(), 1u);
    const int orientation = *is.orientations.begin();
    EXPECT_EQ(orientation, (key.first + key.second) % 2) << "90° between neighbouring islands";
    EXPECT_EQ(is.marks, 25);
    // Along the lines the marks span the island exactly; across, 24 spacings.
    const Vector2d extent = is.hi - is.lo;
    EXPECT_NEAR(extent[orientation], island, kSpacing);
    EXPECT_NEAR(extent[1 - orientation], 24 * 100e-6, kSpacing);
    EXPECT_NEAR(is.lo[orientation], origin[orientation] + island * (orientation == 0 ? key.second : key.first), 1e-15);
  }
  // On the L and the circle: islands clipped, everything inside.
  for (const Shape& shape : testShapes())
    expectWellFormed(chessboard(shape, style(100e-6, 0.2, false), 0.002), shape, style(100e-6, 0.2, false));
}

TEST(ScanGenerators, ContoursAreClosedAtTheirOffsets)
{
  const HatchStyle s = style(100e-6, 0.0, true);
  const Shape rect = makeRectangle(0.010, 0.006);
  const Job job = contours(rect, 3, 0.0005, s);
  expectWellFormed(job, rect, s);
  const auto m = marks(job);
  ASSERT_EQ(m.size(), 3u);
  for (std::size_t k = 0; k < 3; ++k)
  {
    EXPECT_EQ(m[k]->points.front(), m[k]->points.back());
    for (const Vector2d& p : m[k]->points)
      EXPECT_NEAR(distanceToBoundary(rect, p), 0.0005 * (k + 1), 1e-15);  // rounding of mm
  }
  EXPECT_EQ(job.polylines.size(), 5u);  // mark, jump, mark, jump, mark
  // Offsets beyond the inradius are omitted: 2 mm wide, 0.3 mm apart → 0.3, 0.6, 0.9 mm.
  EXPECT_EQ(marks(contours(makeRectangle(0.002, 0.010), 5, 0.0003, s)).size(), 3u);
  // L-shape: every contour edge at its offset from the boundary (measured at edge midpoints).
  const Shape l = readPolygonFile(kData + "polygon_l_shape.txt");
  const Job lj = contours(l, 2, 0.0004, s);
  expectWellFormed(lj, l, s);
  const auto lm = marks(lj);
  ASSERT_EQ(lm.size(), 2u);
  for (std::size_t k = 0; k < 2; ++k)
    for (std::size_t i = 1; i < lm[k]->points.size(); ++i)
      EXPECT_NEAR(distanceToBoundary(l, 0.5 * (lm[k]->points[i - 1] + lm[k]->points[i])), 0.0004 * (k + 1), 1e-15);
  // Circle and holed square: inside, closed.
  for (const Shape& shape : testShapes())
  {
    const Job cj = contours(shape, 2, 0.0003, s);
    expectWellFormed(cj, shape, s);
    for (const Polyline* c : marks(cj))
      EXPECT_EQ(c->points.front(), c->points.back());
  }
  EXPECT_THROW(contours(rect, 0, 0.001, s), ConfigError);
  EXPECT_THROW(contours(rect, 1, 0.004, s), InputError);
}

TEST(ScanGenerators, RectangularSpiralKeepsItsPitch)
{
  const Shape rect = makeRectangle(0.010, 0.006, Vector2d(0.001, 0.0));
  const HatchStyle s = style(200e-6, 0.0, true);
  const Job job = spiral(rect, s);
  expectWellFormed(job, rect, s);
  ASSERT_EQ(job.polylines.size(), 1u);
  const auto& p = job.polylines[0].points;
  ASSERT_GT(p.size(), 50u);
  // Segments i and i + 4 are parallel, one lap apart: exactly one pitch (perpendicular distance).
  for (std::size_t i = 0; i + 5 < p.size(); ++i)
  {
    const Vector2d dir = (p[i + 1] - p[i]).normalized();
    const Vector2d n(-dir.y(), dir.x());
    ASSERT_NEAR((p[i + 4] - p[i]).dot(n), 200e-6, kSpacing) << "segment " << i;
    ASSERT_LT(std::fabs((p[i + 5] - p[i + 4]).normalized().dot(n)), 1e-9);  // same direction
  }
  EXPECT_NEAR(distanceToBoundary(rect, p.front()), 100e-6, 1e-15);  // starts h/2 inside
  // Other shapes: laps at (k + 1/2) h from the boundary.
  const Shape circle = makeCircle(Vector2d::Zero(), 0.003, 1e-6);
  const Job cj = spiral(circle, s);
  expectWellFormed(cj, circle, s);
  const auto laps = marks(cj);
  EXPECT_EQ(laps.size(), 15u);  // offsets 0.1, 0.3, …, 2.9 mm; 3.1 mm exceeds the inradius (≈ 3 mm)
  for (std::size_t k = 0; k < laps.size(); ++k)
    for (const Vector2d& q : laps[k]->points)
      ASSERT_NEAR(distanceToBoundary(circle, q), (k + 0.5) * 200e-6, 1e-15);
  expectWellFormed(spiral(testShapes()[2], s), testShapes()[2], s);
}

TEST(ScanGenerators, HilbertVisitsEveryCellOnce)
{
  const HatchStyle s = style(100e-6, 0.0, true);
  for (const int order : {1, 3, 5})
  {
    const Shape square = makeRectangle(0.008, 0.008, Vector2d(0.001, 0.002));
    const Job job = hilbert(square, order, s);
    expectWellFormed(job, square, s);
    ASSERT_EQ(job.polylines.size(), 1u);  // a square holds its whole curve
    const auto& p = job.polylines[0].points;
    const std::size_t cells = std::size_t(1) << (2 * order);
    ASSERT_EQ(p.size(), cells);
    const double cell = 0.008 / static_cast<double>(1 << order);
    EXPECT_NEAR(length(job.polylines[0]), static_cast<double>(cells - 1) * cell, 1e-12 * 0.008 * cells);
    std::set<std::pair<long, long>> visited;
    for (std::size_t k = 0; k < p.size(); ++k)
    {
      const Vector2d c = (p[k] - Vector2d(-0.003, -0.002)) / cell;
      EXPECT_NEAR(c.x() - std::floor(c.x()), 0.5, 1e-9);  // at cell centres
      visited.insert({static_cast<long>(std::floor(c.x())), static_cast<long>(std::floor(c.y()))});
      if (k > 0)
      {
        ASSERT_NEAR((p[k] - p[k - 1]).norm(), cell, 1e-15);  // to a neighbouring cell
      }
    }
    EXPECT_EQ(visited.size(), cells);
  }
  // Clipped: inside pieces are marks, the gaps jumps; marks shorter than the whole curve.
  for (const Shape& shape : testShapes())
  {
    const Job job = hilbert(shape, 6, s);
    expectWellFormed(job, shape, s);
    double marked = 0.0;
    for (const Polyline* m : marks(job))
      marked += length(*m);
    const Bounds b = shapeBounds(shape);
    const double side = (b.max - b.min).maxCoeff();
    EXPECT_LE(marked, (4096 - 1) * side / 64 * (1 + 1e-12));
  }
  EXPECT_THROW(hilbert(makeRectangle(0.01, 0.01), 11, s), ConfigError);
}

TEST(ScanGenerators, LayerRotation)
{
  const double deg = M_PI / 180.0;
  EXPECT_NEAR(layerAngle(0.0, 1, 67 * deg), 67 * deg, 1e-15);
  EXPECT_NEAR(layerAngle(10 * deg, 6, 67 * deg), 52 * deg, 1e-14);  // 412° → 52°
  EXPECT_NEAR(layerAngle(0.0, 2, -67 * deg), 226 * deg, 1e-14);     // −134° → 226°
  const Shape square = makeRectangle(0.004, 0.004);
  const std::vector<Job> jobs = layers(square, style(100e-6, 0.0, true), 5, 67 * deg);
  ASSERT_EQ(jobs.size(), 5u);
  for (int k = 0; k < 5; ++k)
  {
    const double angle = layerAngle(0.0, k, 67 * deg);
    const Polyline& first = jobs[k].polylines.front();
    const Vector2d dir = first.points.back() - first.points.front();
    // The first mark runs along +d exactly (direction kept, not only the line orientation).
    EXPECT_NEAR(std::remainder(std::atan2(dir.y(), dir.x()) - angle, 2 * M_PI), 0.0, kAngle);
    EXPECT_EQ(jobs[k].name, "hatch_meander_" + square.name + "_layer" + std::to_string(k));
  }
}

TEST(ScanGenerators, BadSettingsNameTheField)
{
  const Shape square = makeRectangle(0.01, 0.01);
  auto message = [&](const HatchStyle& s) {
    try
    {
      hatch(square, s);
    }
    catch (const ConfigError& e)
    {
      return std::string(e.what());
    }
    return std::string();
  };
  HatchStyle s = style(0.0, 0.0, true);
  EXPECT_EQ(message(s), "hatch.spacing_m must be > 0 (got 0)");
  s = style(1e-10, 0.0, true);
  EXPECT_NE(message(s).find("hatch.spacing_m must be > extent / 1e6"), std::string::npos) << message(s);
  s = style(1e-4, 0.0, true);
  s.jump_speed_mps = -1.0;
  EXPECT_EQ(message(s), "hatch.jump_speed_mps must be > 0 (got -1)");
  EXPECT_THROW(stripes(square, style(1e-4, 0, true), 0.0), ConfigError);
  EXPECT_THROW(chessboard(square, style(1e-4, 0, true), 1e-9), ConfigError);
}

TEST(ScanGenerators, EveryGeneratorPassesTheJobValidation)
{
  // The chain's own check (speeds, powers, ≥ 2 finite points, inside a 175 mm half field).
  const HatchStyle s = style(100e-6, 0.5, false);
  for (const Shape& shape : testShapes())
  {
    EXPECT_NO_THROW(validateScanJob(hatch(shape, s), 0.175));
    EXPECT_NO_THROW(validateScanJob(stripes(shape, s, 0.002), 0.175));
    EXPECT_NO_THROW(validateScanJob(chessboard(shape, s, 0.002), 0.175));
    EXPECT_NO_THROW(validateScanJob(contours(shape, 2, 0.0005, s), 0.175));
    EXPECT_NO_THROW(validateScanJob(spiral(shape, s), 0.175));
    EXPECT_NO_THROW(validateScanJob(hilbert(shape, 4, s), 0.175));
  }
}

// The generator's speed is a figure of scanhead_benchmark ("hatch generator"), not a timed test.
