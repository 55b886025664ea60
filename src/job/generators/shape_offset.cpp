// Inward offset of a shape: mitred edge offsets, collapsed edges removed, checked for concave shapes.
#include <algorithm>
#include <cmath>
#include <sstream>

#include "scanhead/common/config_check.hpp"
#include "scanhead/common/errors.hpp"
#include "scanhead/common/number_text.hpp"
#include "scanhead/common/segment_distance.hpp"
#include "scanhead/job/generators/shape.hpp"

namespace scanhead
{
namespace
{
double cross(const Eigen::Vector2d& a, const Eigen::Vector2d& b)
{
  return a.x() * b.y() - a.y() * b.x();
}

/// Drops vertices between two collinear edges of the same direction.
Ring withoutCollinear(const Ring& ring)
{
  Ring out;
  const std::size_t n = ring.size();
  for (std::size_t i = 0; i < n; ++i)
  {
    const Eigen::Vector2d e0 = ring[i] - ring[(i + n - 1) % n];
    const Eigen::Vector2d e1 = ring[(i + 1) % n] - ring[i];
    const bool straight = std::fabs(cross(e0, e1)) <= 1e-14 * e0.norm() * e1.norm() && e0.dot(e1) > 0.0;
    if (!straight)
      out.push_back(ring[i]);
  }
  return out;
}

/// One edge moved inward: a point and the unit direction of the original edge.
struct OffsetLine
{
  Eigen::Vector2d point;
  Eigen::Vector2d direction;
};

Eigen::Vector2d intersect(const OffsetLine& a, const OffsetLine& b)
{
  const double denom = cross(a.direction, b.direction);
  if (std::fabs(denom) < 1e-15)
    return b.point;  // parallel neighbours (a spike): no intersection, keep the later line's anchor
  const double s = cross(b.point - a.point, b.direction) / denom;
  return a.point + s * a.direction;
}

/// Offset of one ring (region on the left) by \p d; empty if it vanishes.
Ring offsetRing(const Ring& input, double d)
{
  const Ring ring = withoutCollinear(input);
  const std::size_t n = ring.size();
  if (n < 3)
    return {};
  std::vector<OffsetLine> lines(n);
  for (std::size_t i = 0; i < n; ++i)
  {
    const Eigen::Vector2d dir = (ring[(i + 1) % n] - ring[i]).normalized();
    lines[i] = {ring[i] + d * Eigen::Vector2d(-dir.y(), dir.x()), dir};
  }
  std::vector<std::size_t> active(n);
  for (std::size_t i = 0; i < n; ++i)
    active[i] = i;
  Ring vertices;
  while (active.size() >= 3)
  {
    const std::size_t m = active.size();
    vertices.resize(m);
    for (std::size_t j = 0; j < m; ++j)
      vertices[j] = intersect(lines[active[(j + m - 1) % m]], lines[active[j]]);
    // An edge whose offset runs backwards has collapsed: remove the most reversed one and redo.
    std::size_t worst = m;
    double worst_length = 0.0;
    std::size_t reversed = 0;
    for (std::size_t j = 0; j < m; ++j)
    {
      const double length = (vertices[(j + 1) % m] - vertices[j]).dot(lines[active[j]].direction);
      if (length <= 0.0)
      {
        ++reversed;
        if (worst == m || length < worst_length)
        {
          worst = j;
          worst_length = length;
        }
      }
    }
    if (worst == m)
      return vertices;
    if (reversed == m)
      return {};  // every edge collapsed at once (e.g. a regular polygon offset by its inradius)
    active.erase(active.begin() + static_cast<std::ptrdiff_t>(worst));
  }
  return {};
}

bool segmentsCross(const Eigen::Vector2d& p1, const Eigen::Vector2d& p2, const Eigen::Vector2d& q1,
                   const Eigen::Vector2d& q2)
{
  const double d1 = cross(p2 - p1, q1 - p1);
  const double d2 = cross(p2 - p1, q2 - p1);
  const double d3 = cross(q2 - q1, p1 - q1);
  const double d4 = cross(q2 - q1, p2 - q1);
  return ((d1 > 0.0 && d2 < 0.0) || (d1 < 0.0 && d2 > 0.0)) && ((d3 > 0.0 && d4 < 0.0) || (d3 < 0.0 && d4 > 0.0));
}

/// Minimum distance between two segments: 0 if they cross, else reached at one of the four ends.
double segmentDistance(const Eigen::Vector2d& p1, const Eigen::Vector2d& p2, const Eigen::Vector2d& q1,
                       const Eigen::Vector2d& q2)
{
  if (segmentsCross(p1, p2, q1, q2))
    return 0.0;
  return std::min(std::min(pointSegmentDistance(p1, q1, q2), pointSegmentDistance(p2, q1, q2)),
                  std::min(pointSegmentDistance(q1, p1, p2), pointSegmentDistance(q2, p1, p2)));
}

double signedArea2(const Ring& ring)
{
  double sum = 0.0;
  for (std::size_t i = 0, n = ring.size(); i < n; ++i)
    sum += cross(ring[i], ring[(i + 1) % n]);
  return sum;
}

/// The checks that make a non-convex offset trustworthy (see offsetInward).
void checkOffset(const Shape& original, const Shape& result, double d)
{
  const std::string what = "inward offset of " + fullPrecisionText(d) + " m of shape '" + original.name + "'";
  std::vector<std::pair<Eigen::Vector2d, Eigen::Vector2d>> edges;
  for (const Ring& ring : result.rings)
    for (std::size_t i = 0, n = ring.size(); i < n; ++i)
      edges.emplace_back(ring[i], ring[(i + 1) % n]);
  for (std::size_t a = 0; a < edges.size(); ++a)
    for (std::size_t b = a + 1; b < edges.size(); ++b)
      if (segmentsCross(edges[a].first, edges[a].second, edges[b].first, edges[b].second))
        throw NumericalError(what + " crosses itself near (" + fullPrecisionText(edges[a].first.x()) + ", " +
                             fullPrecisionText(edges[a].first.y()) +
                             ") m: the offset is larger than a local feature of the shape");
  for (const Ring& ring : result.rings)
    for (const Eigen::Vector2d& p : ring)
      if (!containsPoint(original, p))
        throw NumericalError(what + " has the vertex (" + fullPrecisionText(p.x()) + ", " + fullPrecisionText(p.y()) +
                             ") m outside the shape: the offset is larger than a local feature of the shape");
  // Every offset edge keeps at least the distance from every original edge (exact segment distance).
  const double floor_m = d * (1.0 - 1e-9) - 1e-15;
  for (const auto& edge : edges)
    for (const Ring& ring : original.rings)
      for (std::size_t i = 0, n = ring.size(); i < n; ++i)
        if (segmentDistance(edge.first, edge.second, ring[i], ring[(i + 1) % n]) < floor_m)
          throw NumericalError(what + " has an edge from (" + fullPrecisionText(edge.first.x()) + ", " +
                               fullPrecisionText(edge.first.y()) +
                               ") m closer than the offset to the boundary: the offset is larger than a local "
                               "feature of the shape");
}
}  // namespace

Shape offsetInward(const Shape& shape, double distance_m)
{
  requireSetting(distance_m > 0.0, "contours.offset_m", "> 0", distance_m);
  Shape out;
  out.name = shape.name + "_offset";
  out.source = shape.source + ", offset inward by " + fullPrecisionText(distance_m) + " m";
  std::vector<Ring> rings(shape.rings.size());
  std::vector<bool> keep(shape.rings.size(), true);
  for (std::size_t r = 0; r < shape.rings.size(); ++r)
  {
    rings[r] = offsetRing(shape.rings[r], distance_m);
    if (!rings[r].empty() && (signedArea2(rings[r]) > 0.0) != (signedArea2(shape.rings[r]) > 0.0))
      rings[r].clear();  // turned inside out: nothing of it is left
    if (!rings[r].empty())
      continue;
    keep[r] = false;
    Shape alone;
    alone.rings.push_back(shape.rings[r]);
    for (std::size_t o = 0; o < shape.rings.size(); ++o)
      if (o != r && containsPoint(alone, shape.rings[o][0]))
        keep[o] = false;  // a hole or island of a vanished ring goes with it
  }
  // A filled ring swallowed by one of its grown holes has nothing left between them: drop it
  // with everything nested in it.
  for (std::size_t r = 0; r < rings.size(); ++r)
  {
    if (!keep[r])
      continue;
    Shape alone;
    alone.rings.push_back(shape.rings[r]);
    for (std::size_t h = 0; h < rings.size(); ++h)
    {
      if (h == r || !keep[h] || !containsPoint(alone, shape.rings[h][0]))
        continue;  // not nested in r
      Shape grown;
      grown.rings.push_back(rings[h]);
      if (!containsPoint(grown, rings[r][0]))
        continue;
      for (std::size_t o = 0; o < rings.size(); ++o)
        if (o == r || containsPoint(alone, shape.rings[o][0]))
          keep[o] = false;
      break;
    }
  }
  for (std::size_t r = 0; r < rings.size(); ++r)
    if (keep[r])
      out.rings.push_back(std::move(rings[r]));
  const bool convex = isConvex(shape);
  if (!convex && !out.rings.empty())
    checkOffset(shape, out, distance_m);
  return out;
}
}  // namespace scanhead
