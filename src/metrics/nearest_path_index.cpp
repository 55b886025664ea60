/// \file nearest_path_index.cpp
/// \brief Nearest-path grid index: build by counting sort, refinement, ring search.
#include "scanhead/metrics/nearest_path_index.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <tuple>

#include "contour_error_text.hpp"
#include "scanhead/common/errors.hpp"
#include "scanhead/common/segment_distance.hpp"

namespace scanhead
{
namespace
{
constexpr std::uint32_t kChildFlag = 0x80000000u;  ///< item is a refined cell: low bits = grid index
constexpr std::uint32_t kPointFlag = 0x40000000u;  ///< segment of zero length (the point alone)
constexpr std::uint32_t kIdMask = 0x3fffffffu;
constexpr std::size_t kMaxPoints = std::size_t(1) << 30;

constexpr std::size_t kMaxCellsPerGrid = 4096;
constexpr double kTargetPerCell = 4.0;    ///< segments per cell a grid is sized for
constexpr std::size_t kRefineAbove = 12;  ///< a leaf with more segments is refined if that helps
constexpr std::size_t kDeduplicateAbove = 8;
constexpr int kMaxDepth = 10;

/// Distance from p to the box [x0, x1] × [y0, y1] (0 inside).
inline double boxDistance(const Eigen::Vector2d& p, double x0, double y0, double x1, double y1)
{
  const double dx = std::max({x0 - p.x(), p.x() - x1, 0.0});
  const double dy = std::max({y0 - p.y(), p.y() - y1, 0.0});
  return std::sqrt(dx * dx + dy * dy);
}

/// Cell of coordinate v along an axis of n cells from lo, clamped to [0, n−1].
inline std::uint32_t cellOf(double v, double lo, double inv_cell, std::uint32_t n)
{
  const double u = (v - lo) * inv_cell;
  if (!(u > 0.0))
    return 0;
  if (u >= static_cast<double>(n))
    return n - 1;
  return std::min(static_cast<std::uint32_t>(u), n - 1);
}
}  // namespace

struct NearestPathIndex::Box
{
  double x0, y0, x1, y1;
};

namespace
{
/// Liang–Barsky: the parameter range [t0, t1] ⊂ [0, 1] of a + t·d inside [lo, hi] along one axis.
inline bool clipAxis(double a, double d, double lo, double hi, double& t0, double& t1)
{
  if (d == 0.0)
    return a >= lo && a <= hi;
  double ta = (lo - a) / d;
  double tb = (hi - a) / d;
  if (ta > tb)
    std::swap(ta, tb);
  t0 = std::max(t0, ta);
  t1 = std::min(t1, tb);
  return t0 <= t1;
}

/// Calls f(cell) for every cell of the nx × ny grid (corner x0, y0, side h) that the segment
/// [a, b] crosses or passes within \p margin of (conservative supercover).
template <class F>
void forEachCell(const Eigen::Vector2d& a, const Eigen::Vector2d& b, double x0, double y0, double h, double inv,
                 std::uint32_t nx, std::uint32_t ny, double margin, F&& f)
{
  const Eigen::Vector2d d = b - a;
  double t0 = 0.0, t1 = 1.0;
  if (!clipAxis(a.x(), d.x(), x0 - margin, x0 + nx * h + margin, t0, t1) ||
      !clipAxis(a.y(), d.y(), y0 - margin, y0 + ny * h + margin, t0, t1))
    return;
  const Eigen::Vector2d c0 = a + t0 * d;
  const Eigen::Vector2d c1 = a + t1 * d;
  const std::uint32_t j0 = cellOf(std::min(c0.y(), c1.y()) - margin, y0, inv, ny);
  const std::uint32_t j1 = cellOf(std::max(c0.y(), c1.y()) + margin, y0, inv, ny);
  for (std::uint32_t j = j0; j <= j1; ++j)
  {
    double xa = std::min(c0.x(), c1.x());
    double xb = std::max(c0.x(), c1.x());
    if (j0 != j1 && d.y() != 0.0)
    {
      // Part of the clipped segment inside row j's slab (widened by the margin).
      double s0 = t0, s1 = t1;
      if (!clipAxis(a.y(), d.y(), y0 + j * h - margin, y0 + (j + 1) * h + margin, s0, s1))
        continue;
      const double u0 = a.x() + s0 * d.x();
      const double u1 = a.x() + s1 * d.x();
      xa = std::min(u0, u1);
      xb = std::max(u0, u1);
    }
    const std::uint32_t i0 = cellOf(xa - margin, x0, inv, nx);
    const std::uint32_t i1 = cellOf(xb + margin, x0, inv, nx);
    for (std::uint32_t i = i0; i <= i1; ++i)
      f(static_cast<std::size_t>(j) * nx + i);
  }
}
}  // namespace

inline void NearestPathIndex::elementEnds(std::uint32_t element, Eigen::Vector2d& a, Eigen::Vector2d& b) const
{
  const std::size_t i = element & kIdMask;
  a = path_->point(i);
  b = (element & kPointFlag) ? a : path_->point(i + 1);
}

inline double NearestPathIndex::elementDistance(std::uint32_t element, const Eigen::Vector2d& p) const
{
  const std::size_t i = element & kIdMask;
  if (element & kPointFlag)
    return (path_->point(i) - p).squaredNorm();
  // pointSegmentDistance (segment_distance.hpp) before its square root.
  const Eigen::Vector2d a = path_->point(i);
  const Eigen::Vector2d ab = path_->point(i + 1) - a;
  const double len2 = ab.squaredNorm();
  const double t = len2 > 0.0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
  return (a + t * ab - p).squaredNorm();
}

NearestPathIndex::NearestPathIndex(const PathPoints& path)
  : path_(&path)
  , path_points_(path.size())
{
  const std::size_t n = path.size();
  if (n > kMaxPoints)
  {
    throw InputError("contour error: actual path of " + std::to_string(n) + " points is too long for the index (max " +
                     std::to_string(kMaxPoints) + ")");
  }
  // Elements: segment i → i+1, or the isolated point i. A zero-length segment whose point ends the
  // previous segment adds nothing (by induction on i, the previous point is always covered).
  std::vector<std::uint32_t> elements;
  elements.reserve(n);
  Box box{std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity(),
          -std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity()};
  for (std::size_t i = 0; i < n; ++i)
  {
    const Eigen::Vector2d a = path.point(i);
    const bool joins = path.joinsNext(i);
    const bool zero_length = !joins || path.point(i + 1) == a;
    if (zero_length && i > 0 && path.joinsNext(i - 1))
      continue;
    elements.push_back(static_cast<std::uint32_t>(i) | (zero_length ? kPointFlag : 0u));
    const Eigen::Vector2d b = zero_length ? a : path.point(i + 1);
    box.x0 = std::min({box.x0, a.x(), b.x()});
    box.y0 = std::min({box.y0, a.y(), b.y()});
    box.x1 = std::max({box.x1, a.x(), b.x()});
    box.y1 = std::max({box.y1, a.y(), b.y()});
  }
  indexed_segments_ = elements.size();
  if (elements.empty())
    return;
  duplicate_budget_ = 2 * elements.size();
  buildGrid(elements, box, 0, true);
}

bool NearestPathIndex::buildGrid(const std::vector<std::uint32_t>& elements, const Box& region, int depth, bool top)
{
  const double k = static_cast<double>(elements.size());
  const double w = region.x1 - region.x0;
  const double hgt = region.y1 - region.y0;
  double l1 = 0.0;
  for (std::uint32_t e : elements)
  {
    Eigen::Vector2d a, b;
    elementEnds(e, a, b);
    l1 += std::min(std::abs(b.x() - a.x()), w) + std::min(std::abs(b.y() - a.y()), hgt);
  }
  const double cells = std::clamp(k / kTargetPerCell, 1.0, static_cast<double>(kMaxCellsPerGrid));
  double h = std::max({std::sqrt(w * hgt / cells), std::max(w, hgt) / cells, l1 / (3.0 * k)});
  if (!(h > 0.0))
    h = 1.0;  // every element at one point: one cell
  // h ≥ extent / cells: at most kMaxCellsPerGrid + 1 cells along an axis, and they cover the region.
  const auto axisCells = [&](double extent) { return static_cast<std::uint32_t>(std::floor(extent / h) + 1.0); };
  Grid g;
  g.x0 = region.x0;
  g.y0 = region.y0;
  g.cell_m = h;
  g.inv_cell = 1.0 / h;
  g.nx = axisCells(w);
  g.ny = axisCells(hgt);
  g.rx0 = region.x0;
  g.ry0 = region.y0;
  g.rx1 = region.x1;
  g.ry1 = region.y1;
  const std::size_t ncells = static_cast<std::size_t>(g.nx) * g.ny;
  if (!top && ncells < 2)
    return false;
  const double margin = 1e-6 * h + 1e-15 * (std::abs(g.x0) + std::abs(g.y0) + w + hgt);

  // Counting sort, pass 1: ids per cell.
  std::vector<std::uint32_t> start(ncells + 1, 0);
  for (std::uint32_t e : elements)
  {
    Eigen::Vector2d a, b;
    elementEnds(e, a, b);
    forEachCell(a, b, g.x0, g.y0, h, g.inv_cell, g.nx, g.ny, margin, [&](std::size_t c) { ++start[c + 1]; });
  }
  std::size_t total = 0, most = 0;
  for (std::size_t c = 0; c < ncells; ++c)
  {
    most = std::max<std::size_t>(most, start[c + 1]);
    total += start[c + 1];
    start[c + 1] = static_cast<std::uint32_t>(total);
    if (total > std::numeric_limits<std::uint32_t>::max())
      throw InputError("contour error: actual path too large for the index (more than 2^32 cell entries)");
  }
  if (!top)
  {
    // Refine only if it splits the cell's contents and the duplicates fit the budget.
    const std::size_t extra = total > elements.size() ? total - elements.size() : 0;
    if (most >= elements.size() || extra > duplicate_budget_)
      return false;
    duplicate_budget_ -= extra;
  }
  // Pass 2: fill.
  std::vector<std::uint32_t> sorted(total);
  {
    std::vector<std::uint32_t> next(start.begin(), start.end() - 1);
    for (std::uint32_t e : elements)
    {
      Eigen::Vector2d a, b;
      elementEnds(e, a, b);
      forEachCell(a, b, g.x0, g.y0, h, g.inv_cell, g.nx, g.ny, margin, [&](std::size_t c) { sorted[next[c]++] = e; });
    }
  }
  g.first_offset = offsets_.size();
  grids_.push_back(g);
  offsets_.resize(offsets_.size() + ncells + 1);

  std::vector<std::uint32_t> cell;
  for (std::size_t c = 0; c < ncells; ++c)
  {
    const std::size_t here = items_.size();
    if (here > std::numeric_limits<std::uint32_t>::max())
      throw InputError("contour error: actual path too large for the index (more than 2^32 cell entries)");
    offsets_[g.first_offset + c] = static_cast<std::uint32_t>(here);
    cell.assign(sorted.begin() + start[c], sorted.begin() + start[c + 1]);
    if (cell.empty())
      continue;
    // Refine a crowded cell; if that does not split it, drop repeated segments (a spot at rest)
    // and try again.
    const auto refine = [&]() {
      if (cell.size() <= kRefineAbove || depth >= kMaxDepth)
        return false;
      // The cell's box (widened by the margin) ∩ the box of its segments holds every part of them
      // that lies in this cell: the child grid covers that.
      const std::size_t ci = c % g.nx, cj = c / g.nx;
      Box sub{g.x0 + ci * h - margin, g.y0 + cj * h - margin, g.x0 + (ci + 1) * h + margin,
              g.y0 + (cj + 1) * h + margin};
      Box ext{std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity(),
              -std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity()};
      for (std::uint32_t e : cell)
      {
        Eigen::Vector2d a, b;
        elementEnds(e, a, b);
        ext.x0 = std::min({ext.x0, a.x(), b.x()});
        ext.y0 = std::min({ext.y0, a.y(), b.y()});
        ext.x1 = std::max({ext.x1, a.x(), b.x()});
        ext.y1 = std::max({ext.y1, a.y(), b.y()});
      }
      sub.x0 = std::max(sub.x0, ext.x0);
      sub.y0 = std::max(sub.y0, ext.y0);
      sub.x1 = std::min(sub.x1, ext.x1);
      sub.y1 = std::min(sub.y1, ext.y1);
      if (!(sub.x0 <= sub.x1 && sub.y0 <= sub.y1))
        return false;
      items_.push_back(kChildFlag | static_cast<std::uint32_t>(grids_.size()));
      if (buildGrid(cell, sub, depth + 1, false))
        return true;
      items_.pop_back();
      return false;
    };
    if (refine())
      continue;
    if (cell.size() > kDeduplicateAbove)
    {
      const std::size_t before = cell.size();
      removeDuplicates(cell);
      if (cell.size() < before && refine())
        continue;
    }
    emitLeaf(cell);
  }
  offsets_[g.first_offset + ncells] = static_cast<std::uint32_t>(items_.size());
  return true;
}

void NearestPathIndex::removeDuplicates(std::vector<std::uint32_t>& elements) const
{
  // Identical stored segments (a spot at rest, a trace repeated) are kept once; order kept.
  using Key = std::tuple<double, double, double, double>;
  std::vector<std::pair<Key, std::uint32_t>> keyed;
  keyed.reserve(elements.size());
  for (std::uint32_t e : elements)
  {
    Eigen::Vector2d a, b;
    elementEnds(e, a, b);
    if (std::make_pair(b.x(), b.y()) < std::make_pair(a.x(), a.y()))
      std::swap(a, b);
    keyed.emplace_back(Key{a.x(), a.y(), b.x(), b.y()}, e);
  }
  std::sort(keyed.begin(), keyed.end());
  elements.clear();
  for (std::size_t k = 0; k < keyed.size(); ++k)
    if (k == 0 || keyed[k].first != keyed[k - 1].first)
      elements.push_back(keyed[k].second);
  std::sort(elements.begin(), elements.end());
}

void NearestPathIndex::emitLeaf(const std::vector<std::uint32_t>& elements)
{
  largest_leaf_ = std::max(largest_leaf_, elements.size());
  items_.insert(items_.end(), elements.begin(), elements.end());
}

double NearestPathIndex::distance(const Eigen::Vector2d& p, double upper_bound_m, NearestPathWork* work,
                                  NearestPathHint* hint) const
{
  if (!p.allFinite())
    throw InputError("contour error: commanded point " + pointText(p) + " m is not finite");
  if (!(upper_bound_m >= 0.0))
    throw InputError("contour error: upper bound " + fullPrecisionText(upper_bound_m) + " m is negative or NaN");
  double best = upper_bound_m;
  if (grids_.empty())
    return best;
  if (hint && p.x() - best >= hint->x0 && p.x() + best <= hint->x1 && p.y() - best >= hint->y0 &&
      p.y() + best <= hint->y1)
  {
    // The bound's disc lies inside the last leaf: no segment outside it can be nearer than the bound.
    if (work && hint->begin < hint->end)
    {
      ++work->cells_visited;
      work->segments_tested += hint->end - hint->begin;
    }
    return leafDistance(hint->begin, hint->end, p, best);  // an empty leaf: best
  }
  const double inf = std::numeric_limits<double>::infinity();
  search(0, p, best, work, hint, Box{-inf, -inf, inf, inf});
  return best;
}

double NearestPathIndex::leafDistance(std::uint32_t begin, std::uint32_t end, const Eigen::Vector2d& p,
                                      double best) const
{
  // min over the cell of √(d²) = √(min d²) (√ is monotone and correctly rounded): one root per cell.
  double best2 = std::numeric_limits<double>::infinity();
  for (std::uint32_t k = begin; k < end; ++k)
    best2 = std::min(best2, elementDistance(items_[k], p));
  return std::min(best, std::sqrt(best2));
}

void NearestPathIndex::search(std::size_t grid, const Eigen::Vector2d& p, double& best, NearestPathWork* work,
                              NearestPathHint* hint, const Box& within) const
{
  const Grid& g = grids_[grid];
  if (boxDistance(p, g.rx0, g.ry0, g.rx1, g.ry1) >= best)
    return;
  // The part of the plane whose segments this grid lists all: its region within its ancestors' (a refined cell's
  // grid covers that cell's box, whose last row and column may reach past its own grid's region).
  const Box area{std::max(within.x0, g.rx0), std::max(within.y0, g.ry0), std::min(within.x1, g.rx1),
                 std::min(within.y1, g.ry1)};
  const double h = g.cell_m;
  const long nx = g.nx, ny = g.ny;
  const long ci = cellOf(p.x(), g.x0, g.inv_cell, g.nx);
  const long cj = cellOf(p.y(), g.y0, g.inv_cell, g.ny);
  const double ex1 = g.x0 + nx * h, ey1 = g.y0 + ny * h;
  const auto visit = [&](long i, long j) {
    if (boxDistance(p, g.x0 + i * h, g.y0 + j * h, g.x0 + (i + 1) * h, g.y0 + (j + 1) * h) < best)
      visitCell(g, static_cast<std::size_t>(j * nx + i), p, best, work, nullptr, area);
  };
  const long rmax = std::max({ci, nx - 1 - ci, cj, ny - 1 - cj});
  for (long r = 0; r <= rmax; ++r)
  {
    const long ilo = std::max(ci - r, 0L), ihi = std::min(ci + r, nx - 1);
    if (r > 0)
    {
      // Cells not yet read lie outside rings 0…r−1, i.e. in the strips of the grid around them.
      const long ilo1 = std::max(ci - r + 1, 0L), ihi1 = std::min(ci + r - 1, nx - 1);
      const long jlo1 = std::max(cj - r + 1, 0L), jhi1 = std::min(cj + r - 1, ny - 1);
      const double sx0 = g.x0 + ilo1 * h, sx1 = g.x0 + (ihi1 + 1) * h;
      const double sy0 = g.y0 + jlo1 * h, sy1 = g.y0 + (jhi1 + 1) * h;
      double outside = std::numeric_limits<double>::infinity();
      if (ilo1 > 0)
        outside = std::min(outside, boxDistance(p, g.x0, g.y0, sx0, ey1));
      if (ihi1 < nx - 1)
        outside = std::min(outside, boxDistance(p, sx1, g.y0, ex1, ey1));
      if (jlo1 > 0)
        outside = std::min(outside, boxDistance(p, sx0, g.y0, sx1, sy0));
      if (jhi1 < ny - 1)
        outside = std::min(outside, boxDistance(p, sx0, sy1, sx1, ey1));
      if (outside >= best)
        break;
    }
    if (r == 0)
    {
      // The cell of p (clamped to the grid): the hint records it if it is a leaf that holds p, its box clipped to
      // the area whose segments the grid lists.
      const double cx0 = g.x0 + ci * h, cy0 = g.y0 + cj * h, cx1 = g.x0 + (ci + 1) * h, cy1 = g.y0 + (cj + 1) * h;
      const bool holds = p.x() >= cx0 && p.x() <= cx1 && p.y() >= cy0 && p.y() <= cy1;
      const std::size_t cell = static_cast<std::size_t>(cj * nx + ci);
      if (hint && holds)
      {
        const std::uint32_t begin = offsets_[g.first_offset + cell], end = offsets_[g.first_offset + cell + 1];
        if (begin == end || !(items_[begin] & kChildFlag))
          *hint = NearestPathHint{std::max(cx0, area.x0),
                                  std::max(cy0, area.y0),
                                  std::min(cx1, area.x1),
                                  std::min(cy1, area.y1),
                                  begin,
                                  end};
      }
      if (boxDistance(p, cx0, cy0, cx1, cy1) < best)
        visitCell(g, cell, p, best, work, holds ? hint : nullptr, area);
      continue;
    }
    if (cj - r >= 0)
      for (long i = ilo; i <= ihi; ++i)
        visit(i, cj - r);
    if (cj + r < ny)
      for (long i = ilo; i <= ihi; ++i)
        visit(i, cj + r);
    const long jb = std::max(cj - r + 1, 0L), je = std::min(cj + r - 1, ny - 1);
    if (ci - r >= 0)
      for (long j = jb; j <= je; ++j)
        visit(ci - r, j);
    if (ci + r < nx)
      for (long j = jb; j <= je; ++j)
        visit(ci + r, j);
  }
}

void NearestPathIndex::visitCell(const Grid& g, std::size_t cell, const Eigen::Vector2d& p, double& best,
                                 NearestPathWork* work, NearestPathHint* hint, const Box& within) const
{
  const std::uint32_t begin = offsets_[g.first_offset + cell];
  const std::uint32_t end = offsets_[g.first_offset + cell + 1];
  if (begin == end)
    return;
  if (work)
    ++work->cells_visited;
  if (items_[begin] & kChildFlag)
  {
    search(items_[begin] & ~kChildFlag, p, best, work, hint, within);
    return;
  }
  best = leafDistance(begin, end, p, best);
  if (work)
    work->segments_tested += end - begin;
}

std::size_t NearestPathIndex::memoryBytes() const
{
  return sizeof(*this) + grids_.capacity() * sizeof(Grid) + offsets_.capacity() * sizeof(std::uint32_t) +
         items_.capacity() * sizeof(std::uint32_t);
}
}  // namespace scanhead
