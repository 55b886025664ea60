/// \file shape.hpp
/// \brief Closed planar regions for the scan-path generators: rectangles, polygonised circles and
/// polygons read from text files; point-in-region, clipping of segments, inward offsets.
///
/// A Shape is one or more closed rings filled by the even-odd rule, so a ring inside another is a
/// hole (and a ring inside a hole an island). Rings are stored without the closing vertex and
/// oriented so that the region is on the left of every edge (outer rings counter-clockwise,
/// holes clockwise), which makes "inward" the left normal of every edge.
///
/// Polygon file format (readPolygonFile), all coordinates in metres, work-plane frame:
/// \code
/// # L-shape, 10 mm arms, 4 mm thick        <- '#' starts a comment (whole line or after the numbers)
/// 0.000 0.000                              <- one vertex per line: "x y", separated by blanks
/// 0.010 0.000
/// 0.010 0.004
/// 0.004 0.004
/// 0.004 0.010
/// 0.000 0.010                              <- the ring closes by itself; repeating the first
///                                             vertex at the end is allowed and dropped
///                                          <- a blank line ends the ring; the next vertices start
/// 0.001 0.001                                 a new ring (a hole if inside the first, even-odd)
/// ...
/// \endcode
/// Each ring needs at least 3 vertices and a non-zero area. The layout is that of a gnuplot data
/// file, so `plot "file" with lines` draws the shape (without the closing edges).
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

namespace scanhead
{
/// \brief A closed polygon: vertices [m], without the repeated closing vertex.
using Ring = std::vector<Eigen::Vector2d>;

/// \brief A region of the work plane: rings filled by the even-odd rule (see the file comment).
struct Shape
{
  std::string name;         ///< short identifier, used in job names
  std::string source;       ///< where it came from (file path or description)
  std::vector<Ring> rings;  ///< region on the left of every edge (outer CCW, holes CW)
};

/// \brief Axis-aligned bounding box [m].
struct Bounds
{
  Eigen::Vector2d min = Eigen::Vector2d::Zero();
  Eigen::Vector2d max = Eigen::Vector2d::Zero();
};

/// \brief Part [t0, t1] of a segment a + t (b − a), 0 <= t0 < t1 <= 1.
struct SegmentInterval
{
  double t0 = 0.0;
  double t1 = 0.0;
};

/// \brief Rectangle \p width_m × \p height_m centred on \p centre_m, edges along x and y.
/// \throws ConfigError "shape.width_m must be > 0 (got …)" (and height_m)
Shape makeRectangle(double width_m, double height_m, const Eigen::Vector2d& centre_m = Eigen::Vector2d::Zero());

/// \brief Circle of radius \p radius_m as an inscribed regular polygon whose chords deviate from
/// the circle by at most \p chord_tolerance_m (the sagitta):
/// \f[ r\,(1 - \cos(\pi / n)) \le \varepsilon \;\Rightarrow\; n = \lceil \pi / \arccos(1 - \varepsilon / r) \rceil,
///     \; n \ge 8 \f]
/// Every vertex lies on the circle, so the polygon lies inside it.
/// \throws ConfigError for a non-positive radius or tolerance, or more than 1e6 vertices
Shape makeCircle(const Eigen::Vector2d& centre_m, double radius_m, double chord_tolerance_m);

/// \brief A shape from rings: drops repeated closing and consecutive duplicate vertices,
/// orients the rings (see Shape).
/// \throws InputError "<name>: ring k: …" for fewer than 3 distinct vertices, a non-finite
/// coordinate or a zero area
Shape makePolygon(std::vector<Ring> rings, const std::string& name, const std::string& source);

/// \brief Parses the polygon text format of the file comment; \p source names the text in errors.
/// \throws InputError "source:line: what was expected, got '…'"
Shape parsePolygonText(const std::string& text, const std::string& source);

/// \brief Reads and parses a polygon file (format in the file comment); the shape is named after
/// the file's stem. \throws InputError naming the path (and the line)
Shape readPolygonFile(const std::string& path);

/// \brief Bounding box of all rings.
Bounds shapeBounds(const Shape& shape);

/// \brief Enclosed area [m²] (outer rings minus holes).
double shapeArea(const Shape& shape);

/// \brief True if the single-ring shape is convex (collinear vertices allowed).
bool isConvex(const Shape& shape);

/// \brief Even-odd point-in-region test (crossing number). Points on the boundary may go either way;
/// use distanceOutside() with a tolerance for those.
bool containsPoint(const Shape& shape, const Eigen::Vector2d& point_m);

/// \brief Distance [m] from \p point_m to the nearest edge of any ring.
double distanceToBoundary(const Shape& shape, const Eigen::Vector2d& point_m);

/// \brief 0 if \p point_m is inside, else its distance [m] to the boundary.
double distanceOutside(const Shape& shape, const Eigen::Vector2d& point_m);

/// \brief The parts of the segment \p a_m → \p b_m inside the shape (even-odd), in increasing t,
/// adjacent parts merged. The crossing parameters with every edge split the segment; each piece is
/// classified by its midpoint, so lines through vertices and concave or holed shapes need no
/// special case. Pieces shorter than 1e-12 of the segment are dropped.
std::vector<SegmentInterval> clipSegment(const Shape& shape, const Eigen::Vector2d& a_m, const Eigen::Vector2d& b_m);

/// \brief clipSegment() and containsPoint() for many queries on one shape: the edges are sorted
/// once into horizontal bands, so a query visits only the edges of the bands it spans (a hatch
/// line or a Hilbert step touches few) instead of all edges. Same results as the free functions,
/// bit for bit. Keeps a reference to \p shape, which must outlive it.
class ShapeClipper
{
public:
  explicit ShapeClipper(const Shape& shape);
  bool contains(const Eigen::Vector2d& point_m) const;
  /// \brief Same as clipSegment(shape, a_m, b_m).
  std::vector<SegmentInterval> clip(const Eigen::Vector2d& a_m, const Eigen::Vector2d& b_m) const;

private:
  struct Edge
  {
    Eigen::Vector2d from;  ///< ring[i]
    Eigen::Vector2d to;    ///< ring[i + 1]
  };
  std::size_t bandOf(double y_m) const;
  std::vector<Edge> edges_;
  std::vector<std::size_t> band_start_;  ///< edges of band k: band_edges_[band_start_[k] … band_start_[k + 1])
  std::vector<std::size_t> band_edges_;
  std::size_t band_count_ = 1;
  double y0_m_ = 0.0;
  double band_height_m_ = 1.0;
  double y1_m_ = 0.0;
};

/// \brief Inward offset (erosion) of the shape by \p distance_m > 0: every edge moved by the
/// distance along its inward normal, neighbouring edges re-intersected (mitred corners). Edges that
/// shrink to nothing are removed and the rest re-intersected, so convex polygons stay exact until
/// they vanish; a ring that vanishes is dropped together with the rings nested in it, and an empty
/// shape (no rings) is returned when nothing is left. For a convex corner the mitred vertex is at
/// exactly \p distance_m from both edges; at a reflex corner (concave shapes) the mitre lies
/// farther than \p distance_m from the corner (the exact erosion would have an arc there).
/// A filled ring swallowed whole by one of its growing holes is dropped with its holes.
/// For non-convex shapes the result is checked: no crossing edges, every vertex inside the shape
/// and every offset edge at least \p distance_m (less 1e-9 relative) from every original edge.
/// \throws NumericalError if that check fails (offset larger than a local feature of the shape)
/// \throws ConfigError for a non-positive or non-finite distance
Shape offsetInward(const Shape& shape, double distance_m);
}  // namespace scanhead
