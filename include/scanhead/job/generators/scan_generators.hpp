/// \file scan_generators.hpp
/// \brief The standard LPBF scan strategies as Jobs: hatching (meander or unidirectional raster),
/// stripes, chessboard islands, contour offsets, spiral, Hilbert fill, hatch rotation between layers.
///
/// Common to every generator (SI units, work-plane frame):
/// - a MARK polyline at \c mark_speed_mps and \c power_w for every piece of path inside the shape;
/// - between two marks whose ends differ, an explicit two-point JUMP polyline at \c jump_speed_mps
///   (power 0) from the end of one to the start of the next; the job starts with a mark;
/// - every generated point lies inside the shape (clipped points lie on its boundary, to rounding);
/// - pieces shorter than 1 nm are dropped.
///
/// Hatch geometry (SPEC §5, the hatching of LPBF slicers): the hatch direction is
/// \f$ \mathbf{d} = (\cos\theta, \sin\theta) \f$ and lines are stacked along the left normal
/// \f$ \mathbf{n} = (-\sin\theta, \cos\theta) \f$ at \f[ s_k = \bar s + \left(k - \tfrac{N-1}{2}\right) h,
/// \quad N = \max\!\left(1, \left\lfloor \frac{s_{\max} - s_{\min}}{h} \right\rfloor\right) \f]
/// where \f$ [s_{\min}, s_{\max}] \f$ is the extent of the hatched area (shape or island) along
/// \f$ \mathbf{n} \f$ and \f$ \bar s \f$ its middle: the lines are centred, about h/2 from the edges.
/// Lines are scanned in increasing s; the first goes along +d. Meander: every other line reversed,
/// each joined to the next by a short jump. Unidirectional raster: every line along +d, with a jump
/// back to the start of the next. A line cut into several pieces by a concave shape or a hole gives
/// one mark per piece, in the line's scan direction.
#pragma once

#include <vector>

#include "scanhead/job/generators/shape.hpp"
#include "scanhead/job/scan_job.hpp"

namespace scanhead
{
/// \brief Hatch parameters and the recipe the marks and jumps are made with.
struct HatchStyle
{
  double spacing_m = 100e-6;    ///< hatch distance h between neighbouring lines [m], > 0
  double angle_rad = 0.0;       ///< hatch direction θ from +x, counter-clockwise [rad]
  bool meander = true;          ///< true: serpentine; false: unidirectional raster
  double mark_speed_mps = 1.0;  ///< marking speed [m/s], > 0
  double jump_speed_mps = 4.5;  ///< jump speed [m/s], > 0
  double power_w = 200.0;       ///< laser power on marks [W], >= 0

  /// \throws ConfigError "hatch.<field> must be … (got …)"
  void validate() const;
};

/// \brief Parallel lines at style.angle_rad, style.spacing_m apart (see the file comment), clipped
/// to the shape, each piece a mark, in scan order.
/// \throws ConfigError for a bad style or more than 1e6 lines
Job hatch(const Shape& shape, const HatchStyle& style);

/// \brief Stripe strategy: the hatch of hatch() cut into stripes of width \p stripe_width_m
/// bounded by lines perpendicular to the hatch lines (so no mark is longer than the width); the
/// stripes are taken one after the other in increasing \f$ \mathbf{p}\cdot\mathbf{d} \f$ (the first
/// starts at the shape's minimum along d), all lines of a stripe in increasing s, meander or raster
/// inside the stripe.
/// \throws ConfigError for a bad style, stripe_width_m <= 0 or more than 1e6 stripes
Job stripes(const Shape& shape, const HatchStyle& style, double stripe_width_m);

/// \brief Chessboard (island) strategy: axis-aligned square islands of side \p island_size_m on a
/// grid anchored at the shape's bounding-box minimum corner; island (i, j) (i along x, j along y)
/// is hatched as hatch() hatches the island square (lines centred on the island), clipped to the
/// shape, at angle style.angle_rad + π/2 when i + j is odd, so neighbouring islands differ by 90°.
/// Islands are taken row by row from the bottom (j), left to right (i); islands wholly outside the
/// shape are skipped.
/// \throws ConfigError for a bad style, island_size_m <= 0 or more than 1e6 islands
Job chessboard(const Shape& shape, const HatchStyle& style, double island_size_m);

/// \brief \p count inward offsets of the boundary: contour k = 1…count at the inward distance
/// k · \p offset_m (offsetInward()), outermost first, each ring one closed MARK (first vertex
/// repeated at the end). Contours that vanish (offset beyond the shape's inradius) are omitted,
/// so the job may hold fewer rings. style.spacing_m, angle_rad and meander are not used.
/// \throws ConfigError for a bad style, count < 1 or > 10000, offset_m <= 0
/// \throws NumericalError if an offset of a concave shape would cross itself (see offsetInward())
/// \throws InputError if no contour is left
Job contours(const Shape& shape, int count, double offset_m, const HatchStyle& style);

/// \brief Inward spiral at the pitch style.spacing_m. For a rectangle (one ring of 4 vertices at
/// right angles, any orientation) one MARK: it starts at the corner of its first edge, inset by
/// h/2 from both sides, follows the edges counter-clockwise and turns inward by h after each lap,
/// so neighbouring parallel segments are exactly h apart, until the inner rectangle closes.
/// Other shapes: concentric inward offsets at (k + 1/2) h, k = 0, 1, …, each a closed MARK that
/// starts at its vertex nearest to the end of the previous one, joined by short jumps, until the
/// offset vanishes (for a concave shape: or until the next offset would cross itself).
/// style.angle_rad and meander are not used.
/// \throws ConfigError for a bad style or more than 1e6 laps
Job spiral(const Shape& shape, const HatchStyle& style);

/// \brief Hilbert-curve fill (a fractal scan): the curve of order \p order (1…10) through the
/// centres of the \f$ 2^{o} \times 2^{o} \f$ cells of the shape's bounding square (side = the larger
/// side of the bounding box, same centre), cell size \f$ c = \text{side} / 2^{o} \f$, curve length
/// \f$ (4^{o} - 1)\,c \f$. The curve is clipped to the shape: runs inside are marks, the gaps become
/// straight jumps from the exit to the next entry point. style.spacing_m, angle_rad and meander are
/// not used.
/// \throws ConfigError for a bad style or an order outside 1…10
Job hilbert(const Shape& shape, int order, const HatchStyle& style);

/// \brief Hatch angle of layer \p layer (0-based): \f[ \theta_\ell = (\theta_0 + \ell\,\Delta\theta) \bmod 2\pi
/// \f] in [0, 2π) (the usual slicer rotation is Δθ = 67°, so the direction repeats only after 360
/// layers). The modulo keeps the scan direction: θ and θ + π hatch the same lines in opposite order.
double layerAngle(double base_angle_rad, int layer, double rotation_rad);

/// \brief \p count layers of hatch(): one Job per layer (layer ℓ at layerAngle(style.angle_rad, ℓ,
/// \p rotation_rad), named "<hatch name>_layer<ℓ>"), since a scan job holds a single layer and the
/// CAM node runs one layer at a time.
/// \throws ConfigError for a bad style or count < 1 or > 100000
std::vector<Job> layers(const Shape& shape, const HatchStyle& style, int count, double rotation_rad);
}  // namespace scanhead
