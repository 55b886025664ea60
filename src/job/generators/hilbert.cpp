// Hilbert-curve (fractal) fill clipped to a shape.
#include <algorithm>
#include <cmath>
#include <cstdint>

#include "mark_jump_builder.hpp"
#include "scanhead/common/config_check.hpp"
#include "scanhead/common/errors.hpp"
#include "scanhead/common/number_text.hpp"
#include "scanhead/job/generators/scan_generators.hpp"

namespace scanhead
{
namespace
{
/// Cell (x, y) of index \p d along the Hilbert curve of side \p n = 2^order (the iterative
/// conversion of Hilbert's construction, rotating each quadrant as it descends).
void hilbertCell(std::uint32_t n, std::uint64_t d, std::uint32_t& x, std::uint32_t& y)
{
  x = 0;
  y = 0;
  std::uint64_t t = d;
  for (std::uint32_t s = 1; s < n; s *= 2)
  {
    const std::uint32_t rx = 1u & static_cast<std::uint32_t>(t / 2);
    const std::uint32_t ry = 1u & static_cast<std::uint32_t>(t ^ rx);
    if (ry == 0)
    {
      if (rx == 1)
      {
        x = s - 1 - x;
        y = s - 1 - y;
      }
      std::swap(x, y);
    }
    x += s * rx;
    y += s * ry;
    t /= 4;
  }
}
}  // namespace

Job hilbert(const Shape& shape, int order, const HatchStyle& style)
{
  style.validate();
  if (order < 1 || order > 10)
    failSetting("hilbert.order", "in 1...10", order);
  if (shape.rings.empty())
    throw InputError("shape '" + shape.name + "' (" + shape.source + ") has no ring to scan");
  const Bounds bounds = shapeBounds(shape);
  const double side = (bounds.max - bounds.min).maxCoeff();
  const Eigen::Vector2d corner = 0.5 * (bounds.min + bounds.max) - Eigen::Vector2d::Constant(0.5 * side);
  const std::uint32_t n = 1u << order;
  const double cell = side / static_cast<double>(n);
  const std::uint64_t cells = static_cast<std::uint64_t>(n) * n;
  MarkJumpBuilder out(style, "hilbert" + std::to_string(order) + "_" + shape.name,
                      "generated Hilbert curve of order " + std::to_string(order) + " (cell " +
                          significantText(cell, 12) + " m) clipped to " + shape.source + ": mark " +
                          significantText(style.mark_speed_mps, 12) + " m/s at " + significantText(style.power_w, 12) +
                          " W, jump " + significantText(style.jump_speed_mps, 12) + " m/s");
  auto centre = [&](std::uint64_t d) -> Eigen::Vector2d {
    std::uint32_t x = 0, y = 0;
    hilbertCell(n, d, x, y);
    return corner + cell * Eigen::Vector2d(static_cast<double>(x) + 0.5, static_cast<double>(y) + 0.5);
  };
  const ShapeClipper clipper(shape);
  std::vector<Eigen::Vector2d> run;  // the mark being built: open while the curve stays inside
  Eigen::Vector2d p = centre(0);
  for (std::uint64_t d = 0; d + 1 < cells; ++d)
  {
    const Eigen::Vector2d q = centre(d + 1);
    for (const SegmentInterval& piece : clipper.clip(p, q))
    {
      const Eigen::Vector2d start = piece.t0 == 0.0 ? p : Eigen::Vector2d(p + piece.t0 * (q - p));
      const Eigen::Vector2d end = piece.t1 == 1.0 ? q : Eigen::Vector2d(p + piece.t1 * (q - p));
      if (!(piece.t0 == 0.0 && !run.empty() && run.back() == p))
      {
        out.mark(run);  // the curve left the shape: the gap becomes the jump to `start`
        run.assign(1, start);
      }
      run.push_back(end);
    }
    p = q;
  }
  out.mark(run);
  if (out.empty())
    throw InputError("hilbert curve of order " + std::to_string(order) + " misses shape '" + shape.name +
                     "' (cells of " + significantText(cell, 12) + " m; raise hilbert.order)");
  return out.take();
}
}  // namespace scanhead
