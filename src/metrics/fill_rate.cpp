/// \file fill_rate.cpp
/// \brief Fill-rate grid (THESIS §2.5): 2-bit cells marked by the exact sweep of the spot disc.
#include "scanhead/metrics/fill_rate.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>

#include "contour_error_text.hpp"
#include "scanhead/common/errors.hpp"
#include "scanhead/common/number_text.hpp"

namespace scanhead
{
namespace
{
// Geometry is done in cell units relative to the origin: cell (c, r) is the unit square
// [c, c+1] × [r, r+1] and the spot radius is exactly 0.5.
constexpr double kRadius = 0.5;
constexpr double kRadius2 = kRadius * kRadius;
constexpr double kSubStep = 0.5 * kRadius;  // sub-segments of at most w/2: at most 3 × 3 candidate cells
constexpr double kMaxCells = 2147483648.0;  // 2^31 cells = 512 MiB of bits
constexpr double kMaxSide = 2147483647.0;   // a side must fit an int

double pointBoxDistance2(const Eigen::Vector2d& p, double x0, double y0)
{
  const double dx = std::max({x0 - p.x(), 0.0, p.x() - (x0 + 1.0)});
  const double dy = std::max({y0 - p.y(), 0.0, p.y() - (y0 + 1.0)});
  return dx * dx + dy * dy;
}

double pointSegmentDistance2(const Eigen::Vector2d& p, const Eigen::Vector2d& a, const Eigen::Vector2d& b)
{
  const Eigen::Vector2d ab = b - a;
  const double len2 = ab.squaredNorm();
  const double t = len2 > 0.0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
  return (a + t * ab - p).squaredNorm();
}

/// \brief Liang–Barsky: clips a→b to the box [lo, hi]; false if nothing of the segment is inside.
bool clipToBox(Eigen::Vector2d& a, Eigen::Vector2d& b, const Eigen::Vector2d& lo, const Eigen::Vector2d& hi)
{
  const Eigen::Vector2d d = b - a;
  double t0 = 0.0, t1 = 1.0;
  for (int axis = 0; axis < 2; ++axis)
  {
    const double p[2] = {-d[axis], d[axis]};
    const double q[2] = {a[axis] - lo[axis], hi[axis] - a[axis]};
    for (int k = 0; k < 2; ++k)
    {
      if (p[k] == 0.0)
      {
        if (q[k] < 0.0)
          return false;  // parallel to this edge and outside it
        continue;
      }
      const double t = q[k] / p[k];
      if (p[k] < 0.0)
        t0 = std::max(t0, t);
      else
        t1 = std::min(t1, t);
    }
  }
  if (t0 > t1)
    return false;
  const Eigen::Vector2d a0 = a;
  if (t0 > 0.0)
    a = a0 + t0 * d;
  if (t1 < 1.0)
    b = a0 + t1 * d;
  return true;
}

/// \brief Squared distance between the segment a→b and the unit square at (x0, y0) (0 if they meet).
double segmentBoxDistance2(const Eigen::Vector2d& a, const Eigen::Vector2d& b, double x0, double y0)
{
  const double da = pointBoxDistance2(a, x0, y0);
  const double db = pointBoxDistance2(b, x0, y0);
  if (da == 0.0 || db == 0.0)
    return 0.0;
  Eigen::Vector2d ca = a, cb = b;
  if (clipToBox(ca, cb, Eigen::Vector2d(x0, y0), Eigen::Vector2d(x0 + 1.0, y0 + 1.0)))
    return 0.0;
  // Disjoint convex sets: the closest pair has a vertex of one of them.
  double best = std::min(da, db);
  for (int corner = 0; corner < 4; ++corner)
  {
    const Eigen::Vector2d c(x0 + (corner & 1), y0 + (corner >> 1));
    best = std::min(best, pointSegmentDistance2(c, a, b));
  }
  return best;
}
}  // namespace

FillRateGrid::FillRateGrid(const Eigen::Vector2d& min_corner, const Eigen::Vector2d& max_corner, double spot_diameter_m)
  : origin_(min_corner)
  , pitch_(spot_diameter_m)
{
  if (!(spot_diameter_m > 0.0) || !std::isfinite(spot_diameter_m))
  {
    throw ConfigError("fill rate: the spot diameter (cell pitch) must be finite and > 0 (got " +
                      fullPrecisionText(spot_diameter_m) + " m)");
  }
  if (!min_corner.allFinite() || !max_corner.allFinite() || (max_corner.array() < min_corner.array()).any())
  {
    throw InputError("fill rate: grid bounds must be finite with max >= min (got min " + pointText(min_corner) +
                     " m, max " + pointText(max_corner) + " m)");
  }
  // ceil with a 1e-9 cell tolerance: a 7 mm box at 70 µm is 100 cells, not 101 by rounding.
  const double w = std::max(1.0, std::ceil((max_corner.x() - min_corner.x()) / spot_diameter_m - 1e-9));
  const double h = std::max(1.0, std::ceil((max_corner.y() - min_corner.y()) / spot_diameter_m - 1e-9));
  if (!(w * h <= kMaxCells) || w > kMaxSide || h > kMaxSide)
  {
    std::ostringstream msg;
    msg << "fill rate: a spot diameter of " << fullPrecisionText(spot_diameter_m) << " m over " << pointText(min_corner)
        << " .. " << pointText(max_corner) << " m gives " << w << " x " << h
        << " cells (limit 2^31 cells, 2^31 - 1 a side)";
    throw ConfigError(msg.str());
  }
  width_ = static_cast<int>(w);
  height_ = static_cast<int>(h);
  const std::size_t cells = static_cast<std::size_t>(width_) * static_cast<std::size_t>(height_);
  bits_.assign((cells + 31) / 32, 0);
}

void FillRateGrid::addCommanded(const Eigen::Vector2d& p, bool laser_on)
{
  add(commanded_, p, laser_on, kToFill, "commanded");
}

void FillRateGrid::addActual(const Eigen::Vector2d& p, bool laser_on)
{
  add(actual_, p, laser_on, kReached, "actual");
}

void FillRateGrid::breakCommanded()
{
  commanded_.joinable = false;
}

void FillRateGrid::breakActual()
{
  actual_.joinable = false;
}

void FillRateGrid::reset()
{
  std::fill(bits_.begin(), bits_.end(), 0);
  to_fill_ = reached_in_ = reached_out_ = 0;
  commanded_ = PathState();
  actual_ = PathState();
}

double FillRateGrid::fillRate() const
{
  if (to_fill_ == 0)
    return std::numeric_limits<double>::quiet_NaN();
  return static_cast<double>(reached_in_) / static_cast<double>(to_fill_);
}

std::size_t FillRateGrid::memoryBytes() const
{
  return sizeof(*this) + bits_.capacity() * sizeof(std::uint64_t);
}

std::uint8_t FillRateGrid::cellState(int col, int row) const
{
  if (col < 0 || col >= width_ || row < 0 || row >= height_)
  {
    throw std::out_of_range("fill rate: cell (" + std::to_string(col) + ", " + std::to_string(row) +
                            ") is outside the " + std::to_string(width_) + " x " + std::to_string(height_) + " grid");
  }
  const std::size_t cell = static_cast<std::size_t>(row) * static_cast<std::size_t>(width_) + col;
  return static_cast<std::uint8_t>((bits_[cell >> 5] >> (2 * (cell & 31))) & 3u);
}

void FillRateGrid::add(PathState& state, const Eigen::Vector2d& p, bool laser_on, std::uint8_t bit, const char* which)
{
  if (!p.allFinite())
    throw InputError(std::string("fill rate: ") + which + " point " + pointText(p) + " m is not finite");
  const Eigen::Vector2d u = (p - origin_) / pitch_;
  if (!u.allFinite())
  {
    // So far away that its cell coordinate overflows: it reaches nothing, and is not joined.
    if (laser_on)
      ++state.outside;
    state.joinable = false;
    return;
  }
  if (laser_on)
  {
    markSegment(state.joinable ? state.last : u, u, bit);
    if (u.x() < kRadius || u.x() > width_ - kRadius || u.y() < kRadius || u.y() > height_ - kRadius)
      ++state.outside;
  }
  state.last = u;
  state.joinable = laser_on;
}

void FillRateGrid::markSegment(Eigen::Vector2d a, Eigen::Vector2d b, std::uint8_t bit)
{
  // Beyond the grid dilated by w nothing can be reached: clip first, so the sub-step count is
  // bounded by the grid's size whatever the points.
  // Both ends a cell or more inside that box: the clip would return them unchanged (t0 = 0, t1 = 1:
  // |hi − a| exceeds |b − a| by a whole cell, far beyond the rounding), so it is skipped.
  const double in_lo = 1.0 - kRadius, in_x = width_ + kRadius - 1.0, in_y = height_ + kRadius - 1.0;
  const bool inside = a.x() >= in_lo && a.x() <= in_x && a.y() >= in_lo && a.y() <= in_y && b.x() >= in_lo &&
                      b.x() <= in_x && b.y() >= in_lo && b.y() <= in_y;
  if (!inside &&
      !clipToBox(a, b, Eigen::Vector2d(-kRadius, -kRadius), Eigen::Vector2d(width_ + kRadius, height_ + kRadius)))
    return;
  const Eigen::Vector2d d = b - a;
  // |d|² ≤ kSubStep² gives √ ≤ kSubStep (√ is correctly rounded, kSubStep² exact): one sub-segment
  // without the root (the common case: a sample step is a fraction of the spot).
  if (d.squaredNorm() <= kSubStep * kSubStep)
  {
    markSubSegment(a, b, bit);
    return;
  }
  const std::int64_t n = std::max<std::int64_t>(1, static_cast<std::int64_t>(std::ceil(d.norm() / kSubStep)));
  Eigen::Vector2d from = a;
  for (std::int64_t k = 1; k <= n; ++k)
  {
    const Eigen::Vector2d to = k == n ? b : Eigen::Vector2d(a + (static_cast<double>(k) / static_cast<double>(n)) * d);
    markSubSegment(from, to, bit);
    from = to;
  }
}

void FillRateGrid::markSubSegment(const Eigen::Vector2d& a, const Eigen::Vector2d& b, std::uint8_t bit)
{
  const int c0 = std::max(0, static_cast<int>(std::floor(std::min(a.x(), b.x()) - kRadius)));
  const int c1 = std::min(width_ - 1, static_cast<int>(std::floor(std::max(a.x(), b.x()) + kRadius)));
  const int r0 = std::max(0, static_cast<int>(std::floor(std::min(a.y(), b.y()) - kRadius)));
  const int r1 = std::min(height_ - 1, static_cast<int>(std::floor(std::max(a.y(), b.y()) + kRadius)));
  for (int r = r0; r <= r1; ++r)
  {
    for (int c = c0; c <= c1; ++c)
    {
      const std::size_t cell = static_cast<std::size_t>(r) * static_cast<std::size_t>(width_) + c;
      if (((bits_[cell >> 5] >> (2 * (cell & 31))) & bit) == 0 && segmentBoxDistance2(a, b, c, r) < kRadius2)
        setBit(cell, bit);  // (cells already marked are skipped: consecutive sub-segments overlap)
    }
  }
}

void FillRateGrid::setBit(std::size_t cell, std::uint8_t bit)
{
  std::uint64_t& word = bits_[cell >> 5];
  const unsigned shift = 2u * static_cast<unsigned>(cell & 31);
  const unsigned old = static_cast<unsigned>((word >> shift) & 3u);
  if (old & bit)
    return;
  word |= static_cast<std::uint64_t>(bit) << shift;
  if (bit == kToFill)
  {
    ++to_fill_;
    if (old & kReached)
    {
      ++reached_in_;
      --reached_out_;
    }
  }
  else if (old & kToFill)
    ++reached_in_;
  else
    ++reached_out_;
}
}  // namespace scanhead
