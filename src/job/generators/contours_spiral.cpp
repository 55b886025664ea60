// Contour offsets and the inward spiral.
#include <algorithm>
#include <cmath>

#include "mark_jump_builder.hpp"
#include "scanhead/common/config_check.hpp"
#include "scanhead/common/errors.hpp"
#include "scanhead/common/number_text.hpp"
#include "scanhead/job/generators/scan_generators.hpp"

namespace scanhead
{
namespace
{
/// The ring as a closed mark starting at vertex \p start.
std::vector<Eigen::Vector2d> closedFrom(const Ring& ring, std::size_t start)
{
  std::vector<Eigen::Vector2d> points;
  points.reserve(ring.size() + 1);
  for (std::size_t k = 0; k <= ring.size(); ++k)
    points.push_back(ring[(start + k) % ring.size()]);
  return points;
}

std::size_t nearestVertex(const Ring& ring, const Eigen::Vector2d& to)
{
  std::size_t best = 0;
  for (std::size_t k = 1; k < ring.size(); ++k)
    if ((ring[k] - to).squaredNorm() < (ring[best] - to).squaredNorm())
      best = k;
  return best;
}

/// True for one ring of 4 vertices with right angles (relative tolerance 1e-12 on the cosine).
bool isRectangle(const Shape& shape)
{
  if (shape.rings.size() != 1 || shape.rings[0].size() != 4)
    return false;
  const Ring& ring = shape.rings[0];
  for (std::size_t i = 0; i < 4; ++i)
  {
    const Eigen::Vector2d e0 = ring[(i + 1) % 4] - ring[i];
    const Eigen::Vector2d e1 = ring[(i + 2) % 4] - ring[(i + 1) % 4];
    if (std::fabs(e0.dot(e1)) > 1e-12 * e0.norm() * e1.norm())
      return false;
  }
  return true;
}

/// The rectangular spiral of spiral() (see the header), in the rectangle's own frame.
std::vector<Eigen::Vector2d> rectangularSpiral(const Ring& ring, double h)
{
  const Eigen::Vector2d origin = ring[0];
  const double width = (ring[1] - ring[0]).norm();
  const double height = (ring[2] - ring[1]).norm();
  const Eigen::Vector2d ex = (ring[1] - ring[0]) / width;
  const Eigen::Vector2d ey = (ring[2] - ring[1]) / height;  // left of ex: the ring is counter-clockwise
  if (!(std::min(width, height) / h <= 2e6))
    failSetting("hatch.spacing_m", "> min(width, height) / 2e6 (at most 1e6 laps)", h);
  double x0 = 0.5 * h, y0 = 0.5 * h, x1 = width - 0.5 * h, y1 = height - 0.5 * h;
  if (x1 < x0)
    x0 = x1 = 0.5 * width;
  if (y1 < y0)
    y0 = y1 = 0.5 * height;
  auto at = [&](double x, double y) -> Eigen::Vector2d { return origin + x * ex + y * ey; };
  const double eps = 1e-9 * h;  // rounding of the running sums, far below any pitch
  std::vector<Eigen::Vector2d> points{at(x0, y0)};
  while (true)
  {
    points.push_back(at(x1, y0));
    y0 += h;
    if (y0 > y1 + eps)
      break;
    points.push_back(at(x1, y1));
    x1 -= h;
    if (x1 < x0 - eps)
      break;
    points.push_back(at(x0, y1));
    y1 -= h;
    if (y1 < y0 - eps)
      break;
    points.push_back(at(x0, y0));
    x0 += h;
    if (x0 > x1 + eps)
      break;
  }
  return points;
}
}  // namespace

Job contours(const Shape& shape, int count, double offset_m, const HatchStyle& style)
{
  style.validate();
  if (count < 1 || count > 10000)
    failSetting("contours.count", "in 1...10000", count);
  requireSetting(offset_m > 0.0, "contours.offset_m", "> 0", offset_m);
  MarkJumpBuilder out(style, "contours_" + shape.name,
                      "generated " + std::to_string(count) + " contours " + significantText(offset_m, 12) +
                          " m apart inside " + shape.source + ": mark " + significantText(style.mark_speed_mps, 12) +
                          " m/s at " + significantText(style.power_w, 12) + " W, jump " +
                          significantText(style.jump_speed_mps, 12) + " m/s");
  out.setRole(PolylineRole::Contour);
  for (int k = 1; k <= count; ++k)
  {
    const Shape ring_set = offsetInward(shape, static_cast<double>(k) * offset_m);
    if (ring_set.rings.empty())
      break;  // vanished: the deeper ones too
    for (const Ring& ring : ring_set.rings)
      out.mark(closedFrom(ring, 0));
  }
  if (out.empty())
    throw InputError("contours of shape '" + shape.name + "': nothing left at the first offset of " +
                     significantText(offset_m, 12) + " m (contours.offset_m larger than the shape's inradius)");
  return out.take();
}

Job spiral(const Shape& shape, const HatchStyle& style)
{
  style.validate();
  if (shape.rings.empty())
    throw InputError("shape '" + shape.name + "' (" + shape.source + ") has no ring to scan");
  const double h = style.spacing_m;
  MarkJumpBuilder out(style, "spiral_" + shape.name,
                      "generated inward spiral of pitch " + significantText(h, 12) + " m inside " + shape.source +
                          ": mark " + significantText(style.mark_speed_mps, 12) + " m/s at " +
                          significantText(style.power_w, 12) + " W, jump " + significantText(style.jump_speed_mps, 12) +
                          " m/s");
  if (isRectangle(shape))
  {
    out.mark(rectangularSpiral(shape.rings[0], h));
    return out.take();
  }
  const Bounds bounds = shapeBounds(shape);
  const double max_laps = std::ceil((bounds.max - bounds.min).maxCoeff() / h) + 1.0;
  if (!(max_laps <= 1e6))
    failSetting("hatch.spacing_m", "> extent / 1e6 (at most 1e6 laps)", h);
  for (long k = 0; k < static_cast<long>(max_laps); ++k)
  {
    Shape lap;
    try
    {
      lap = offsetInward(shape, (static_cast<double>(k) + 0.5) * h);
    }
    catch (const NumericalError&)
    {
      break;  // a concave shape whose next offset would cross itself: the spiral ends here
    }
    if (lap.rings.empty())
      break;
    for (const Ring& ring : lap.rings)
      out.mark(closedFrom(ring, out.empty() ? 0 : nearestVertex(ring, out.position())));
  }
  if (out.empty())
    throw InputError("spiral of shape '" + shape.name + "': nothing left at the first offset of " +
                     significantText(0.5 * h, 12) + " m (hatch.spacing_m larger than the shape)");
  return out.take();
}
}  // namespace scanhead
