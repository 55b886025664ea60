// Hatching strategies: plain hatch (meander / raster), stripes, chessboard islands, layer rotation.
#include <algorithm>
#include <cmath>
#include <limits>

#include "mark_jump_builder.hpp"
#include "scanhead/common/config_check.hpp"
#include "scanhead/common/errors.hpp"
#include "scanhead/common/number_text.hpp"
#include "scanhead/job/generators/scan_generators.hpp"

namespace scanhead
{
namespace
{
constexpr double kMaxLines = 1e6;

/// Hatch frame: direction d of the lines, normal n along which they are stacked.
struct Frame
{
  Eigen::Vector2d d;
  Eigen::Vector2d n;
  explicit Frame(double angle_rad)
    : d(std::cos(angle_rad), std::sin(angle_rad))
    , n(-std::sin(angle_rad), std::cos(angle_rad))
  {
  }
};

/// Extent of \p points along \p axis.
template <class Points>
void extentAlong(const Points& points, const Eigen::Vector2d& axis, double& lo, double& hi)
{
  lo = std::numeric_limits<double>::infinity();
  hi = -lo;
  for (const Eigen::Vector2d& p : points)
  {
    lo = std::min(lo, p.dot(axis));
    hi = std::max(hi, p.dot(axis));
  }
}

std::vector<Eigen::Vector2d> allVertices(const Shape& shape)
{
  std::vector<Eigen::Vector2d> out;
  for (const Ring& ring : shape.rings)
    out.insert(out.end(), ring.begin(), ring.end());
  return out;
}

/// Number of centred lines over an extent (see the header): N = max(1, floor(extent / h)).
long lineCount(double extent_m, double spacing_m)
{
  const double ratio = extent_m / spacing_m;
  if (!(ratio <= kMaxLines))
    failSetting("hatch.spacing_m",
                "> extent / 1e6 = " + significantText(extent_m / kMaxLines, 12) + " m (at most 1e6 lines)", spacing_m);
  // 1e-9 relative: 10 mm / 100 µm must give 100 lines, not 99 by rounding of the ratio.
  return std::max(1L, static_cast<long>(std::floor(ratio * (1.0 + 1e-9))));
}

/// Scans the lines s_k (centred over [s_lo, s_hi]) over [u_lo, u_hi] along d, clipped to the
/// shape, marks in scan order.
void emitHatch(MarkJumpBuilder& out, const ShapeClipper& shape, const Frame& frame, double spacing_m, bool meander,
               double s_lo, double s_hi, double u_lo, double u_hi)
{
  const long count = lineCount(s_hi - s_lo, spacing_m);
  const double s_mid = 0.5 * (s_lo + s_hi);
  const double half = 0.5 * static_cast<double>(count - 1);
  long emitted = 0;
  for (long k = 0; k < count; ++k)
  {
    const double s = s_mid + (static_cast<double>(k) - half) * spacing_m;
    const Eigen::Vector2d a = s * frame.n + u_lo * frame.d;
    const Eigen::Vector2d b = s * frame.n + u_hi * frame.d;
    const std::vector<SegmentInterval> pieces = shape.clip(a, b);
    if (pieces.empty())
      continue;
    const Eigen::Vector2d r = b - a;
    const bool forward = !meander || emitted % 2 == 0;
    ++emitted;
    if (forward)
      for (const SegmentInterval& piece : pieces)
        out.mark(a + piece.t0 * r, a + piece.t1 * r);
    else
      for (auto it = pieces.rbegin(); it != pieces.rend(); ++it)
        out.mark(a + it->t1 * r, a + it->t0 * r);
  }
}

std::string styleText(const HatchStyle& style)
{
  return "spacing " + significantText(style.spacing_m, 12) + " m, angle " + significantText(style.angle_rad, 12) +
         " rad, " + (style.meander ? "meander" : "unidirectional raster") + ", mark " +
         significantText(style.mark_speed_mps, 12) + " m/s at " + significantText(style.power_w, 12) + " W, jump " +
         significantText(style.jump_speed_mps, 12) + " m/s";
}

void requireShape(const Shape& shape)
{
  if (shape.rings.empty())
    throw InputError("shape '" + shape.name + "' (" + shape.source + ") has no ring to scan");
}

/// A rectangle as a Shape (for clipping a line to an island).
Shape boxShape(const Eigen::Vector2d& lo, const Eigen::Vector2d& hi)
{
  Shape box;
  box.rings.push_back({lo, Eigen::Vector2d(hi.x(), lo.y()), hi, Eigen::Vector2d(lo.x(), hi.y())});
  return box;
}
}  // namespace

void HatchStyle::validate() const
{
  requireSetting(spacing_m > 0.0, "hatch.spacing_m", "> 0", spacing_m);
  requireSetting(std::isfinite(angle_rad), "hatch.angle_rad", "finite", angle_rad);
  requireSetting(mark_speed_mps > 0.0, "hatch.mark_speed_mps", "> 0", mark_speed_mps);
  requireSetting(jump_speed_mps > 0.0, "hatch.jump_speed_mps", "> 0", jump_speed_mps);
  requireSetting(power_w >= 0.0, "hatch.power_w", ">= 0", power_w);
}

Job hatch(const Shape& shape, const HatchStyle& style)
{
  style.validate();
  requireShape(shape);
  const Frame frame(style.angle_rad);
  const std::vector<Eigen::Vector2d> vertices = allVertices(shape);
  double s_lo, s_hi, u_lo, u_hi;
  extentAlong(vertices, frame.n, s_lo, s_hi);
  extentAlong(vertices, frame.d, u_lo, u_hi);
  const double margin = 0.01 * (u_hi - u_lo);  // line ends outside the shape: pieces end on edges
  MarkJumpBuilder out(style, std::string("hatch_") + (style.meander ? "meander" : "raster") + "_" + shape.name,
                      "generated hatch of " + shape.source + ": " + styleText(style));
  emitHatch(out, ShapeClipper(shape), frame, style.spacing_m, style.meander, s_lo, s_hi, u_lo - margin, u_hi + margin);
  return out.take();
}

Job stripes(const Shape& shape, const HatchStyle& style, double stripe_width_m)
{
  style.validate();
  requireSetting(stripe_width_m > 0.0, "hatch.stripe_width_m", "> 0", stripe_width_m);
  requireShape(shape);
  const Frame frame(style.angle_rad);
  const std::vector<Eigen::Vector2d> vertices = allVertices(shape);
  double s_lo, s_hi, u_lo, u_hi;
  extentAlong(vertices, frame.n, s_lo, s_hi);
  extentAlong(vertices, frame.d, u_lo, u_hi);
  const double stripe_count_real = std::ceil((u_hi - u_lo) / stripe_width_m);
  if (!(stripe_count_real <= kMaxLines))
    failSetting("hatch.stripe_width_m", "> extent / 1e6 (at most 1e6 stripes)", stripe_width_m);
  const long stripe_count = std::max(1L, static_cast<long>(stripe_count_real));
  MarkJumpBuilder out(style, std::string("stripes_") + (style.meander ? "meander" : "raster") + "_" + shape.name,
                      "generated stripes of " + significantText(stripe_width_m, 12) + " m over " + shape.source + ": " +
                          styleText(style));
  const ShapeClipper clipper(shape);
  for (long j = 0; j < stripe_count; ++j)
  {
    const double lo = u_lo + static_cast<double>(j) * stripe_width_m;
    const double hi = std::min(u_hi, lo + stripe_width_m);
    emitHatch(out, clipper, frame, style.spacing_m, style.meander, s_lo, s_hi, lo, hi);
  }
  return out.take();
}

Job chessboard(const Shape& shape, const HatchStyle& style, double island_size_m)
{
  style.validate();
  requireSetting(island_size_m > 0.0, "hatch.island_size_m", "> 0", island_size_m);
  requireShape(shape);
  const Bounds bounds = shapeBounds(shape);
  const Eigen::Vector2d extent = bounds.max - bounds.min;
  const double nx_real = std::max(1.0, std::ceil(extent.x() / island_size_m * (1.0 - 1e-9)));
  const double ny_real = std::max(1.0, std::ceil(extent.y() / island_size_m * (1.0 - 1e-9)));
  if (!(nx_real * ny_real <= kMaxLines))
    failSetting("hatch.island_size_m", "> extent / 1000 (at most 1e6 islands)", island_size_m);
  const long nx = static_cast<long>(nx_real);
  const long ny = static_cast<long>(ny_real);
  MarkJumpBuilder out(style, std::string("chessboard_") + (style.meander ? "meander" : "raster") + "_" + shape.name,
                      "generated chessboard of " + significantText(island_size_m, 12) + " m islands over " +
                          shape.source + ": " + styleText(style) + ", +90 deg on odd islands");
  const ShapeClipper clipper(shape);
  for (long j = 0; j < ny; ++j)
    for (long i = 0; i < nx; ++i)
    {
      const Eigen::Vector2d lo =
          bounds.min + island_size_m * Eigen::Vector2d(static_cast<double>(i), static_cast<double>(j));
      const Eigen::Vector2d hi = lo + Eigen::Vector2d::Constant(island_size_m);
      const double angle = style.angle_rad + ((i + j) % 2 == 1 ? 0.5 * M_PI : 0.0);
      const Frame frame(angle);
      const Shape box = boxShape(lo, hi);
      double s_lo, s_hi, u_lo, u_hi;
      extentAlong(box.rings[0], frame.n, s_lo, s_hi);
      extentAlong(box.rings[0], frame.d, u_lo, u_hi);
      const double margin = 0.01 * (u_hi - u_lo);
      // Each island line: the part inside the island square, then the parts of that inside the shape.
      const long count = lineCount(s_hi - s_lo, style.spacing_m);
      const double s_mid = 0.5 * (s_lo + s_hi);
      const double half = 0.5 * static_cast<double>(count - 1);
      long emitted = 0;
      for (long k = 0; k < count; ++k)
      {
        const double s = s_mid + (static_cast<double>(k) - half) * style.spacing_m;
        const Eigen::Vector2d a0 = s * frame.n + (u_lo - margin) * frame.d;
        const Eigen::Vector2d b0 = s * frame.n + (u_hi + margin) * frame.d;
        const std::vector<SegmentInterval> in_box = clipSegment(box, a0, b0);
        if (in_box.empty())
          continue;
        const Eigen::Vector2d a = a0 + in_box.front().t0 * (b0 - a0);
        const Eigen::Vector2d b = a0 + in_box.back().t1 * (b0 - a0);
        const std::vector<SegmentInterval> pieces = clipper.clip(a, b);
        if (pieces.empty())
          continue;
        const Eigen::Vector2d r = b - a;
        const bool forward = !style.meander || emitted % 2 == 0;
        ++emitted;
        if (forward)
          for (const SegmentInterval& piece : pieces)
            out.mark(piece.t0 == 0.0 ? a : a + piece.t0 * r, piece.t1 == 1.0 ? b : a + piece.t1 * r);
        else
          for (auto it = pieces.rbegin(); it != pieces.rend(); ++it)
            out.mark(it->t1 == 1.0 ? b : a + it->t1 * r, it->t0 == 0.0 ? a : a + it->t0 * r);
      }
    }
  return out.take();
}

double layerAngle(double base_angle_rad, int layer, double rotation_rad)
{
  const double angle = std::fmod(base_angle_rad + static_cast<double>(layer) * rotation_rad, 2.0 * M_PI);
  return angle < 0.0 ? angle + 2.0 * M_PI : angle;
}

std::vector<Job> layers(const Shape& shape, const HatchStyle& style, int count, double rotation_rad)
{
  if (count < 1 || count > 100000)
    failSetting("hatch.layer_count", "in 1...100000", count);
  requireSetting(std::isfinite(rotation_rad), "hatch.rotation_rad", "finite", rotation_rad);
  std::vector<Job> out;
  out.reserve(static_cast<std::size_t>(count));
  for (int layer = 0; layer < count; ++layer)
  {
    HatchStyle layer_style = style;
    layer_style.angle_rad = layerAngle(style.angle_rad, layer, rotation_rad);
    Job job = hatch(shape, layer_style);
    job.name += "_layer" + std::to_string(layer);
    job.source +=
        ", layer " + std::to_string(layer) + " (rotation " + significantText(rotation_rad, 12) + " rad per layer)";
    out.push_back(std::move(job));
  }
  return out;
}
}  // namespace scanhead
