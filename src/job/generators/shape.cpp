#include "scanhead/job/generators/shape.hpp"
#include "scanhead/common/number_text.hpp"
#include "scanhead/common/segment_distance.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "scanhead/common/config_check.hpp"
#include "scanhead/common/errors.hpp"

namespace scanhead
{
namespace
{
double cross(const Eigen::Vector2d& a, const Eigen::Vector2d& b)
{
  return a.x() * b.y() - a.y() * b.x();
}

/// Twice the signed area (shoelace), > 0 for counter-clockwise.
double signedArea2(const Ring& ring)
{
  double sum = 0.0;
  for (std::size_t i = 0, n = ring.size(); i < n; ++i)
    sum += cross(ring[i], ring[(i + 1) % n]);
  return sum;
}

/// Crossing-number parity of one ring.
bool insideRing(const Ring& ring, const Eigen::Vector2d& p)
{
  bool inside = false;
  for (std::size_t i = 0, n = ring.size(), j = n - 1; i < n; j = i++)
  {
    const Eigen::Vector2d& a = ring[i];
    const Eigen::Vector2d& b = ring[j];
    if ((a.y() > p.y()) != (b.y() > p.y()))
    {
      const double x = a.x() + (b.x() - a.x()) * (p.y() - a.y()) / (b.y() - a.y());
      if (p.x() < x)
        inside = !inside;
    }
  }
  return inside;
}

}  // namespace

Shape makeRectangle(double width_m, double height_m, const Eigen::Vector2d& centre_m)
{
  requireSetting(width_m > 0.0, "shape.width_m", "> 0", width_m);
  requireSetting(height_m > 0.0, "shape.height_m", "> 0", height_m);
  if (!centre_m.allFinite())
    failSetting("shape.centre_m", "finite", centre_m.x() + centre_m.y());
  const double hx = 0.5 * width_m;
  const double hy = 0.5 * height_m;
  Shape shape;
  shape.name = "rectangle_" + fullPrecisionText(width_m) + "x" + fullPrecisionText(height_m) + "m";
  shape.source = "rectangle " + fullPrecisionText(width_m) + " m x " + fullPrecisionText(height_m) + " m centred on (" +
                 fullPrecisionText(centre_m.x()) + ", " + fullPrecisionText(centre_m.y()) + ") m";
  shape.rings.push_back({centre_m + Eigen::Vector2d(-hx, -hy), centre_m + Eigen::Vector2d(hx, -hy),
                         centre_m + Eigen::Vector2d(hx, hy), centre_m + Eigen::Vector2d(-hx, hy)});
  return shape;
}

Shape makeCircle(const Eigen::Vector2d& centre_m, double radius_m, double chord_tolerance_m)
{
  requireSetting(radius_m > 0.0, "shape.radius_m", "> 0", radius_m);
  requireSetting(chord_tolerance_m > 0.0, "shape.chord_tolerance_m", "> 0", chord_tolerance_m);
  if (!centre_m.allFinite())
    failSetting("shape.centre_m", "finite", centre_m.x() + centre_m.y());
  const double ratio = std::min(chord_tolerance_m / radius_m, 1.0);
  const double n_real = std::ceil(M_PI / std::acos(1.0 - ratio));
  if (!(n_real <= 1e6))
    failSetting("shape.chord_tolerance_m", ">= radius × 5e-12 (at most 1e6 vertices)", chord_tolerance_m);
  const std::size_t n = std::max<std::size_t>(8, static_cast<std::size_t>(n_real));
  Shape shape;
  shape.name = "circle_r" + fullPrecisionText(radius_m) + "m";
  shape.source = "circle of radius " + fullPrecisionText(radius_m) + " m centred on (" +
                 fullPrecisionText(centre_m.x()) + ", " + fullPrecisionText(centre_m.y()) + ") m, " +
                 std::to_string(n) + " vertices (chord tolerance " + fullPrecisionText(chord_tolerance_m) + " m)";
  Ring ring(n);
  for (std::size_t k = 0; k < n; ++k)
  {
    const double phi = 2.0 * M_PI * static_cast<double>(k) / static_cast<double>(n);
    ring[k] = centre_m + radius_m * Eigen::Vector2d(std::cos(phi), std::sin(phi));
  }
  shape.rings.push_back(std::move(ring));
  return shape;
}

Shape makePolygon(std::vector<Ring> rings, const std::string& name, const std::string& source)
{
  if (rings.empty())
    throw InputError(source + ": no ring (expected at least 3 vertices 'x y' in m)");
  for (std::size_t r = 0; r < rings.size(); ++r)
  {
    Ring& ring = rings[r];
    const std::string where = source + ": ring " + std::to_string(r + 1);
    for (const Eigen::Vector2d& p : ring)
      if (!p.allFinite())
        throw InputError(where + ": vertex (" + fullPrecisionText(p.x()) + ", " + fullPrecisionText(p.y()) +
                         ") is not finite");
    Ring clean;
    clean.reserve(ring.size());
    for (const Eigen::Vector2d& p : ring)
      if (clean.empty() || p != clean.back())
        clean.push_back(p);
    while (clean.size() > 1 && clean.back() == clean.front())
      clean.pop_back();
    if (clean.size() < 3)
      throw InputError(where + ": " + std::to_string(clean.size()) +
                       " distinct vertices; a closed polygon needs at least 3");
    const double area2 = signedArea2(clean);
    double scale = 0.0;
    for (const Eigen::Vector2d& p : clean)
      scale = std::max(scale, p.cwiseAbs().maxCoeff());
    if (!(std::fabs(area2) > 1e-24 * std::max(scale * scale, 1e-30)))
      throw InputError(where + ": zero area (all vertices on one line)");
    ring = std::move(clean);
  }
  // Orientation from the nesting depth: even depth (filled) counter-clockwise, odd (hole) clockwise.
  std::vector<bool> ccw(rings.size());
  for (std::size_t r = 0; r < rings.size(); ++r)
  {
    std::size_t depth = 0;
    for (std::size_t o = 0; o < rings.size(); ++o)
      if (o != r && insideRing(rings[o], rings[r][0]))
        ++depth;
    ccw[r] = depth % 2 == 0;
  }
  for (std::size_t r = 0; r < rings.size(); ++r)
    if ((signedArea2(rings[r]) > 0.0) != ccw[r])
      std::reverse(rings[r].begin(), rings[r].end());
  Shape shape;
  shape.name = name;
  shape.source = source;
  shape.rings = std::move(rings);
  return shape;
}

Bounds shapeBounds(const Shape& shape)
{
  Bounds b;
  b.min.setConstant(std::numeric_limits<double>::infinity());
  b.max.setConstant(-std::numeric_limits<double>::infinity());
  for (const Ring& ring : shape.rings)
    for (const Eigen::Vector2d& p : ring)
    {
      b.min = b.min.cwiseMin(p);
      b.max = b.max.cwiseMax(p);
    }
  if (shape.rings.empty())
    b = Bounds();
  return b;
}

double shapeArea(const Shape& shape)
{
  double sum = 0.0;
  for (const Ring& ring : shape.rings)
    sum += 0.5 * signedArea2(ring);  // holes are clockwise: negative
  return sum;
}

bool isConvex(const Shape& shape)
{
  if (shape.rings.size() != 1)
    return false;
  const Ring& ring = shape.rings[0];
  const std::size_t n = ring.size();
  for (std::size_t i = 0; i < n; ++i)
  {
    const Eigen::Vector2d e0 = ring[(i + 1) % n] - ring[i];
    const Eigen::Vector2d e1 = ring[(i + 2) % n] - ring[(i + 1) % n];
    if (cross(e0, e1) < -1e-12 * e0.norm() * e1.norm())
      return false;
  }
  return true;
}

bool containsPoint(const Shape& shape, const Eigen::Vector2d& point_m)
{
  bool inside = false;
  for (const Ring& ring : shape.rings)
    if (insideRing(ring, point_m))
      inside = !inside;
  return inside;
}

double distanceToBoundary(const Shape& shape, const Eigen::Vector2d& point_m)
{
  double best = std::numeric_limits<double>::infinity();
  for (const Ring& ring : shape.rings)
    for (std::size_t i = 0, n = ring.size(); i < n; ++i)
      best = std::min(best, pointSegmentDistance(point_m, ring[i], ring[(i + 1) % n]));
  return best;
}

double distanceOutside(const Shape& shape, const Eigen::Vector2d& point_m)
{
  return containsPoint(shape, point_m) ? 0.0 : distanceToBoundary(shape, point_m);
}

std::vector<SegmentInterval> clipSegment(const Shape& shape, const Eigen::Vector2d& a_m, const Eigen::Vector2d& b_m)
{
  const Eigen::Vector2d r = b_m - a_m;
  std::vector<double> cuts{0.0, 1.0};
  for (const Ring& ring : shape.rings)
    for (std::size_t i = 0, n = ring.size(); i < n; ++i)
    {
      const Eigen::Vector2d& c = ring[i];
      const Eigen::Vector2d e = ring[(i + 1) % n] - c;
      const double denom = cross(r, e);
      if (denom == 0.0)
        continue;  // parallel: a collinear overlap is cut by the neighbouring edges
      const Eigen::Vector2d ac = c - a_m;
      const double t = cross(ac, e) / denom;
      const double u = cross(ac, r) / denom;
      if (t > 0.0 && t < 1.0 && u >= 0.0 && u <= 1.0)
        cuts.push_back(t);
    }
  std::sort(cuts.begin(), cuts.end());
  std::vector<SegmentInterval> out;
  constexpr double kMinPiece = 1e-12;  // of the segment: rounding slivers at vertices
  for (std::size_t k = 0; k + 1 < cuts.size(); ++k)
  {
    const double t0 = cuts[k];
    const double t1 = cuts[k + 1];
    if (t1 - t0 <= kMinPiece)
      continue;
    if (!containsPoint(shape, a_m + 0.5 * (t0 + t1) * r))
      continue;
    if (!out.empty() && t0 - out.back().t1 <= kMinPiece)
      out.back().t1 = t1;  // the cut between them was a vertex or a sliver
    else
      out.push_back({t0, t1});
  }
  return out;
}
ShapeClipper::ShapeClipper(const Shape& shape)
{
  for (const Ring& ring : shape.rings)
    for (std::size_t i = 0, n = ring.size(); i < n; ++i)
      edges_.push_back({ring[i], ring[(i + 1) % n]});
  const Bounds bounds = shapeBounds(shape);
  y0_m_ = bounds.min.y();
  y1_m_ = bounds.max.y();
  // About two edges per band for an even spread; at most 4096 bands.
  const std::size_t bands = std::clamp<std::size_t>(edges_.size() / 2, 1, 4096);
  band_count_ = bands;
  band_height_m_ = (y1_m_ - y0_m_) / static_cast<double>(bands);
  if (!(band_height_m_ > 0.0))
    band_height_m_ = 1.0;
  std::vector<std::size_t> count(bands + 1, 0);
  for (int pass = 0; pass < 2; ++pass)
  {
    for (std::size_t e = 0; e < edges_.size(); ++e)
    {
      const std::size_t lo = bandOf(std::min(edges_[e].from.y(), edges_[e].to.y()));
      const std::size_t hi = bandOf(std::max(edges_[e].from.y(), edges_[e].to.y()));
      for (std::size_t k = lo; k <= hi; ++k)
      {
        if (pass == 0)
          ++count[k + 1];
        else
          band_edges_[count[k]++] = e;
      }
    }
    if (pass == 0)
    {
      for (std::size_t k = 0; k < bands; ++k)
        count[k + 1] += count[k];
      band_start_ = count;
      band_edges_.resize(count[bands]);
    }
  }
}

std::size_t ShapeClipper::bandOf(double y_m) const
{
  const double k = std::floor((y_m - y0_m_) / band_height_m_);
  const std::size_t last = band_count_ - 1;
  if (!(k > 0.0))
    return 0;
  return std::min(static_cast<std::size_t>(std::min(k, 1e9)), last);
}

bool ShapeClipper::contains(const Eigen::Vector2d& p) const
{
  if (!(p.y() >= y0_m_ && p.y() <= y1_m_))
    return false;
  // Every edge that crosses the horizontal through p spans p.y, so it lies in p's band.
  bool inside = false;
  const std::size_t band = bandOf(p.y());
  for (std::size_t k = band_start_[band]; k < band_start_[band + 1]; ++k)
  {
    const Edge& edge = edges_[band_edges_[k]];
    const Eigen::Vector2d& a = edge.to;  // the operand order of insideRing(): bit-identical results
    const Eigen::Vector2d& b = edge.from;
    if ((a.y() > p.y()) != (b.y() > p.y()))
    {
      const double x = a.x() + (b.x() - a.x()) * (p.y() - a.y()) / (b.y() - a.y());
      if (p.x() < x)
        inside = !inside;
    }
  }
  return inside;
}

std::vector<SegmentInterval> ShapeClipper::clip(const Eigen::Vector2d& a_m, const Eigen::Vector2d& b_m) const
{
  std::vector<SegmentInterval> out;
  const double y_lo = std::min(a_m.y(), b_m.y());
  const double y_hi = std::max(a_m.y(), b_m.y());
  if (!(y_hi >= y0_m_ && y_lo <= y1_m_) || edges_.empty())
    return out;
  const Eigen::Vector2d r = b_m - a_m;
  std::vector<double> cuts{0.0, 1.0};
  for (std::size_t band = bandOf(y_lo), last = bandOf(y_hi); band <= last; ++band)
    for (std::size_t k = band_start_[band]; k < band_start_[band + 1]; ++k)
    {
      // An edge in several bands adds the same cut several times: zero-length pieces, skipped.
      const Edge& edge = edges_[band_edges_[k]];
      const Eigen::Vector2d& c = edge.from;
      const Eigen::Vector2d e = edge.to - c;
      const double denom = cross(r, e);
      if (denom == 0.0)
        continue;
      const Eigen::Vector2d ac = c - a_m;
      const double t = cross(ac, e) / denom;
      const double u = cross(ac, r) / denom;
      if (t > 0.0 && t < 1.0 && u >= 0.0 && u <= 1.0)
        cuts.push_back(t);
    }
  std::sort(cuts.begin(), cuts.end());
  constexpr double kMinPiece = 1e-12;  // as clipSegment()
  for (std::size_t k = 0; k + 1 < cuts.size(); ++k)
  {
    const double t0 = cuts[k];
    const double t1 = cuts[k + 1];
    if (t1 - t0 <= kMinPiece)
      continue;
    if (!contains(a_m + 0.5 * (t0 + t1) * r))
      continue;
    if (!out.empty() && t0 - out.back().t1 <= kMinPiece)
      out.back().t1 = t1;
    else
      out.push_back({t0, t1});
  }
  return out;
}
}  // namespace scanhead
