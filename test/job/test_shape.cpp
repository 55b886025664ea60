// Shapes: construction, polygon files and their errors, point-in-polygon, clipping, inward offsets.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "scanhead/common/errors.hpp"
#include "scanhead/job/generators/shape.hpp"

using namespace scanhead;
using Eigen::Vector2d;

namespace
{
const std::string kData = std::string(SCANHEAD_SOURCE_DIR) + "/test/data/";

/// The message of the exception E thrown by \p f, or "" if none.
template <class E, class F>
std::string errorOf(F&& f)
{
  try
  {
    f();
  }
  catch (const E& e)
  {
    return e.what();
  }
  return "";
}

bool has(const std::string& text, const std::string& part)
{
  return text.find(part) != std::string::npos;
}
}  // namespace

TEST(Shape, RectangleIsCounterClockwiseWithItsArea)
{
  const Shape r = makeRectangle(0.010, 0.006, Vector2d(0.001, -0.002));
  ASSERT_EQ(r.rings.size(), 1u);
  EXPECT_NEAR(shapeArea(r), 6e-5, 1e-18);  // > 0: counter-clockwise; 1e-18 m² = rounding of mm²
  EXPECT_TRUE(containsPoint(r, Vector2d(0.001, -0.002)));
  EXPECT_TRUE(containsPoint(r, Vector2d(0.0059, 0.0009)));
  EXPECT_FALSE(containsPoint(r, Vector2d(0.0061, 0.0)));
  EXPECT_TRUE(isConvex(r));
  EXPECT_TRUE(has(errorOf<ConfigError>([] { makeRectangle(0.0, 1.0); }), "shape.width_m must be > 0 (got 0)"));
}

TEST(Shape, CircleMeetsItsChordTolerance)
{
  const double r = 0.005;
  for (const double tol : {1e-4, 1e-6, 1e-8})
  {
    const Shape c = makeCircle(Vector2d(0.01, 0.0), r, tol);
    const Ring& ring = c.rings[0];
    const std::size_t n = ring.size();
    double worst_sagitta = 0.0;
    for (std::size_t k = 0; k < n; ++k)
    {
      EXPECT_NEAR((ring[k] - Vector2d(0.01, 0.0)).norm(), r, 1e-15);  // vertices on the circle
      const Vector2d mid = 0.5 * (ring[k] + ring[(k + 1) % n]);
      worst_sagitta = std::max(worst_sagitta, r - (mid - Vector2d(0.01, 0.0)).norm());
    }
    EXPECT_LE(worst_sagitta, tol);
    // Not wastefully fine either: one vertex fewer would break the tolerance.
    EXPECT_GT(r * (1.0 - std::cos(M_PI / static_cast<double>(n - 1))), tol) << "n = " << n;
    EXPECT_LT(shapeArea(c), M_PI * r * r);
  }
}

TEST(Shape, ReadsTheLShapeFixture)
{
  const Shape l = readPolygonFile(kData + "polygon_l_shape.txt");
  EXPECT_EQ(l.name, "polygon_l_shape");
  ASSERT_EQ(l.rings.size(), 1u);
  EXPECT_EQ(l.rings[0].size(), 6u);
  EXPECT_NEAR(shapeArea(l), 6.4e-5, 1e-18);  // 10×4 + 4×6 mm²
  EXPECT_FALSE(isConvex(l));
  EXPECT_TRUE(containsPoint(l, Vector2d(0.002, 0.008)));
  EXPECT_FALSE(containsPoint(l, Vector2d(0.006, 0.006)));  // the notch of the L
  EXPECT_EQ(readPolygonFile(kData + "polygon_minimal.txt").rings[0].size(), 3u);
}

TEST(Shape, HoleRingsAreHolesAndOriented)
{
  const Shape h = readPolygonFile(kData + "polygon_holes_full.txt");
  ASSERT_EQ(h.rings.size(), 2u);
  EXPECT_EQ(h.rings[0].size(), 4u);          // repeated closing vertex dropped
  EXPECT_NEAR(shapeArea(h), 8.4e-5, 1e-18);  // 100 − 16 mm²: outer CCW, hole CW
  EXPECT_FALSE(containsPoint(h, Vector2d(0.0, 0.0)));
  EXPECT_TRUE(containsPoint(h, Vector2d(0.003, 0.0)));
}

TEST(Shape, BadPolygonFilesNameFileLineAndWhatWasExpected)
{
  const std::string few = errorOf<InputError>([] { readPolygonFile(kData + "polygon_invalid_too_few.txt"); });
  EXPECT_TRUE(has(few, "polygon_invalid_too_few.txt:3:")) << few;
  EXPECT_TRUE(has(few, "2 distinct vertices")) << few;
  EXPECT_TRUE(has(few, "at least 3")) << few;

  const std::string nan = errorOf<InputError>([] { readPolygonFile(kData + "polygon_invalid_non_numeric.txt"); });
  EXPECT_TRUE(has(nan, "polygon_invalid_non_numeric.txt:3: y: 'O.002' is not a number")) << nan;

  const std::string three = errorOf<InputError>([] { readPolygonFile(kData + "polygon_invalid_fields.txt"); });
  EXPECT_TRUE(has(three, "polygon_invalid_fields.txt:2: expected two numbers 'x y' (metres)")) << three;

  const std::string missing = errorOf<InputError>([] { readPolygonFile(kData + "no_such_polygon.txt"); });
  EXPECT_TRUE(has(missing, "no_such_polygon.txt: cannot open")) << missing;

  EXPECT_TRUE(has(errorOf<InputError>([] { parsePolygonText("# nothing\n\n", "t.txt"); }), "t.txt:2: no vertices"));
  EXPECT_TRUE(has(errorOf<InputError>([] { parsePolygonText("0 0\n1 1\n2 2\n", "t.txt"); }),
                  "t.txt:3: ring 1 (lines 1-3) encloses no area"));
  EXPECT_TRUE(has(errorOf<InputError>([] { parsePolygonText("0 0\n1 0\n0 1\n\n5 5\n", "t.txt"); }),
                  "t.txt:5: ring 2 (lines 5-5) has 1 distinct vertices"));
  EXPECT_TRUE(has(errorOf<InputError>([] { parsePolygonText("0 0\n1 inf\n0 1\n", "t.txt"); }),
                  "t.txt:2: y: 'inf' is not a finite number"));
  // Crossing or touching edges, within a ring or between rings, name both edges by their lines.
  EXPECT_EQ(errorOf<InputError>([] { parsePolygonText("0 0\n2 2\n2 0\n0 1\n", "t.txt"); }),
            "t.txt:3: the outline crosses itself: ring 1 edge lines 1-2 and ring 1 edge lines 3-4 cross or touch "
            "(rings must be simple and disjoint)");
  EXPECT_TRUE(has(errorOf<InputError>([] { parsePolygonText("0 0\n4 0\n4 4\n0 4\n\n3 1\n5 1\n5 2\n", "t.txt"); }),
                  "ring 1 edge lines 2-3 and ring 2 edge lines 6-7 cross"));
  // A figure 8 pinched at a vertex (touching) and a spike folding back onto its edge.
  EXPECT_TRUE(
      has(errorOf<InputError>([] { parsePolygonText("0 0\n2 0\n1 1\n2 2\n0 2\n1 1\n", "t.txt"); }), "crosses itself"));
  EXPECT_TRUE(has(errorOf<InputError>([] { parsePolygonText("0 0\n2 0\n1 0\n1 1\n", "t.txt"); }), "crosses itself"));
  // Nested rings that do not touch (an island in a hole) are fine; so is a repeated closing vertex.
  EXPECT_EQ(parsePolygonText("0 0\n9 0\n9 9\n0 9\n0 0\n\n1 1\n8 1\n8 8\n1 8\n\n4 4\n5 4\n5 5\n", "t.txt").rings.size(),
            3u);
  // Comments after numbers, tabs and CRLF are fine.
  EXPECT_EQ(parsePolygonText("0\t0 # a\r\n1 0\r\n0 1\r\n", "t.txt").rings[0].size(), 3u);
}

TEST(Shape, ClippingMatchesDenseSamplingOnConcaveAndHoledShapes)
{
  // Independent check: membership of 20001 samples along each segment vs the intervals; samples
  // within 1e-12 of a cut are skipped (boundary points may go either way).
  const Shape shapes[] = {readPolygonFile(kData + "polygon_l_shape.txt"),
                          readPolygonFile(kData + "polygon_holes_full.txt"), makeCircle(Vector2d::Zero(), 0.004, 1e-6)};
  const Vector2d segments[][2] = {{Vector2d(-0.02, 0.006), Vector2d(0.02, 0.006)},
                                  {Vector2d(-0.02, 0.0), Vector2d(0.02, 0.0)},
                                  {Vector2d(-0.01, -0.01), Vector2d(0.012, 0.011)},
                                  {Vector2d(-0.01, 0.004), Vector2d(0.02, 0.004)},   // along an edge of the L
                                  {Vector2d(0.004, -0.01), Vector2d(0.004, 0.02)}};  // through its reflex vertex
  for (const Shape& shape : shapes)
    for (const auto& seg : segments)
    {
      const auto pieces = clipSegment(shape, seg[0], seg[1]);
      for (std::size_t k = 1; k < pieces.size(); ++k)
        EXPECT_GT(pieces[k].t0, pieces[k - 1].t1);  // sorted, disjoint, merged
      const double length = (seg[1] - seg[0]).norm();
      for (int i = 0; i <= 20000; ++i)
      {
        const double t = i / 20000.0;
        bool in = false, near = false;
        for (const auto& p : pieces)
        {
          in = in || (t >= p.t0 && t <= p.t1);
          near = near || std::fabs(t - p.t0) * length < 1e-12 || std::fabs(t - p.t1) * length < 1e-12;
        }
        const Vector2d x = seg[0] + t * (seg[1] - seg[0]);
        if (!near && distanceToBoundary(shape, x) > 1e-12)
        {
          ASSERT_EQ(in, containsPoint(shape, x)) << shape.name << " t = " << t;
        }
      }
    }
  // The L at y = 6 mm: exactly x in [0, 4] mm.
  const auto l = clipSegment(shapes[0], Vector2d(-0.01, 0.006), Vector2d(0.01, 0.006));
  ASSERT_EQ(l.size(), 1u);
  EXPECT_NEAR(l[0].t0 * 0.02 - 0.01, 0.0, 1e-15);
  EXPECT_NEAR(l[0].t1 * 0.02 - 0.01, 0.004, 1e-15);
  // The holed square at y = 0: two pieces.
  EXPECT_EQ(clipSegment(shapes[1], Vector2d(-0.01, 0.0), Vector2d(0.01, 0.0)).size(), 2u);
}

TEST(Shape, ClipperGivesTheSameBitsAsTheFreeFunctions)
{
  // Seeded sweep (seed 6, 3000 segments per shape) over the bounding box and beyond, plus
  // horizontal segments through every vertex (the band edges of the index).
  const Shape shapes[] = {readPolygonFile(kData + "polygon_l_shape.txt"),
                          readPolygonFile(kData + "polygon_holes_full.txt"),
                          makeCircle(Vector2d(0.001, 0.0), 0.004, 1e-7), makeRectangle(0.01, 0.002)};
  std::mt19937_64 rng(6);
  std::uniform_real_distribution<double> coord(-0.008, 0.008);
  for (const Shape& shape : shapes)
  {
    const ShapeClipper clipper(shape);
    std::vector<std::pair<Vector2d, Vector2d>> segments;
    for (int i = 0; i < 3000; ++i)
      segments.emplace_back(Vector2d(coord(rng), coord(rng)), Vector2d(coord(rng), coord(rng)));
    for (const Ring& ring : shape.rings)
      for (const Vector2d& v : ring)
        segments.emplace_back(Vector2d(-0.01, v.y()), Vector2d(0.01, v.y()));
    for (const auto& [a, b] : segments)
    {
      ASSERT_EQ(clipper.contains(a), containsPoint(shape, a));
      const auto x = clipper.clip(a, b);
      const auto y = clipSegment(shape, a, b);
      ASSERT_EQ(x.size(), y.size()) << shape.name;
      for (std::size_t k = 0; k < x.size(); ++k)
      {
        ASSERT_EQ(x[k].t0, y[k].t0);
        ASSERT_EQ(x[k].t1, y[k].t1);
      }
    }
  }
}

TEST(Shape, OffsetOfARectangleIsExact)
{
  const Shape r = makeRectangle(0.010, 0.006);
  const Shape o = offsetInward(r, 0.001);
  ASSERT_EQ(o.rings.size(), 1u);
  ASSERT_EQ(o.rings[0].size(), 4u);
  EXPECT_NEAR(shapeArea(o), 0.008 * 0.004, 1e-18);
  for (const Vector2d& p : o.rings[0])
    EXPECT_NEAR(distanceToBoundary(r, p), 0.001, 1e-15);  // rounding of mm coordinates
  EXPECT_TRUE(offsetInward(r, 0.003).rings.empty());      // = half the height: nothing left
  EXPECT_TRUE(offsetInward(r, 0.004).rings.empty());
  EXPECT_TRUE(has(errorOf<ConfigError>([&] { offsetInward(r, -1.0); }), "must be > 0"));
}

TEST(Shape, OffsetOfACircleKeepsItsDistance)
{
  const Shape c = makeCircle(Vector2d(0.001, 0.002), 0.005, 1e-6);
  for (const double d : {0.0005, 0.002, 0.0049})
  {
    const Shape o = offsetInward(c, d);
    ASSERT_EQ(o.rings.size(), 1u);
    for (const Vector2d& p : o.rings[0])
      EXPECT_NEAR(distanceToBoundary(c, p), d, 1e-15);
  }
  EXPECT_TRUE(offsetInward(c, 0.0051).rings.empty());
}

TEST(Shape, OffsetOfTheLShapeAndOfAHoledSquare)
{
  const Shape l = readPolygonFile(kData + "polygon_l_shape.txt");
  const double d = 0.001;
  const Shape o = offsetInward(l, d);
  ASSERT_EQ(o.rings.size(), 1u);
  ASSERT_EQ(o.rings[0].size(), 6u);
  // Mitred: vertices (1,1) (9,1) (9,3) (3,3) (3,9) (1,9) mm, area 8×2 + 2×6 mm².
  EXPECT_NEAR(shapeArea(o), 2.8e-5, 1e-17);
  for (std::size_t k = 0; k < 6; ++k)
  {
    const Vector2d mid = 0.5 * (o.rings[0][k] + o.rings[0][(k + 1) % 6]);
    EXPECT_NEAR(distanceToBoundary(l, mid), d, 1e-15);  // each edge is d from its original edge
    EXPECT_GE(distanceToBoundary(l, o.rings[0][k]), d - 1e-15);
  }
  const Shape holes = readPolygonFile(kData + "polygon_holes_full.txt");
  const Shape ho = offsetInward(holes, d);
  ASSERT_EQ(ho.rings.size(), 2u);
  EXPECT_NEAR(shapeArea(ho), 0.008 * 0.008 - 0.006 * 0.006, 1e-17);  // outer shrinks, hole grows
  // 2.5 mm: the 3 mm wide frame is gone, with its hole.
  EXPECT_TRUE(offsetInward(holes, 0.0025).rings.empty());
}

TEST(Shape, OffsetThatWouldCrossItselfThrows)
{
  // Dumbbell: two 4 mm squares joined by a 1 mm wide neck. Eroding by more than 0.5 mm splits it.
  const Shape bell = parsePolygonText(
      "0 0\n0.004 0\n0.004 0.0015\n0.006 0.0015\n0.006 0\n0.010 0\n0.010 0.004\n0.006 0.004\n0.006 0.0025\n"
      "0.004 0.0025\n0.004 0.004\n0 0.004\n",
      "dumbbell");
  EXPECT_EQ(offsetInward(bell, 0.0003).rings.size(), 1u);
  const std::string message = errorOf<NumericalError>([&] { offsetInward(bell, 0.0008); });
  EXPECT_TRUE(has(message, "shape 'dumbbell'")) << message;
  EXPECT_TRUE(has(message, "larger than a local feature")) << message;
}
