/// \file nearest_path_index.cpp
/// \brief Nearest-path grid index: build by counting sort, refinement, ring search.
#include "scanhead/metrics/nearest_path_index.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <memory>
#include <mutex>
#include <new>
#include <string>
#include <tuple>

#include <sys/mman.h>
#include <unistd.h>

#include "contour_error_text.hpp"
#include "scanhead/common/errors.hpp"
#include "scanhead/common/segment_distance.hpp"
#include "scanhead/common/side_thread.hpp"

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
constexpr std::size_t kParallelAbove = std::size_t(1) << 16;  ///< fewer segments: one thread (not worth a start)

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
  static Box empty()
  {
    const double inf = std::numeric_limits<double>::infinity();
    return Box{inf, inf, -inf, -inf};
  }
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
  // A segment inside the grid (the usual case) keeps [0, 1] without the divisions: the clip box is wider by the margin.
  const bool inside = std::min(a.x(), b.x()) >= x0 && std::max(a.x(), b.x()) <= x0 + nx * h &&
                      std::min(a.y(), b.y()) >= y0 && std::max(a.y(), b.y()) <= y0 + ny * h;
  if (!inside && (!clipAxis(a.x(), d.x(), x0 - margin, x0 + nx * h + margin, t0, t1) ||
                  !clipAxis(a.y(), d.y(), y0 - margin, y0 + ny * h + margin, t0, t1)))
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

inline void NearestPathIndex::extend(Box& box, std::uint32_t element) const
{
  Eigen::Vector2d a, b;
  elementEnds(element, a, b);
  box.x0 = std::min({box.x0, a.x(), b.x()});
  box.y0 = std::min({box.y0, a.y(), b.y()});
  box.x1 = std::max({box.x1, a.x(), b.x()});
  box.y1 = std::max({box.y1, a.y(), b.y()});
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

template <class F>
void NearestPathIndex::forEachElement(F&& f) const
{
  forEachElementIn(0, path_->size(), f);
}

template <class F>
void NearestPathIndex::forEachElementIn(std::size_t from, std::size_t to, F&& f) const
{
  // A zero-length segment whose point ends the previous segment adds nothing (by induction on i, the previous point
  // is always covered).
  const PathPoints& path = *path_;
  for (std::size_t i = from; i < to; ++i)
  {
    const bool joins = path.joinsNext(i);
    const bool zero_length = !joins || path.point(i + 1) == path.point(i);
    if (zero_length && i > 0 && path.joinsNext(i - 1))
      continue;
    f(static_cast<std::uint32_t>(i) | (zero_length ? kPointFlag : 0u));
  }
}

template <class Each>
NearestPathIndex::Grid NearestPathIndex::layGrid(const Each& each, std::size_t count, const Box& region) const
{
  const double k = static_cast<double>(count);
  const double w = region.x1 - region.x0;
  const double hgt = region.y1 - region.y0;
  double l1 = 0.0;
  each([&](std::uint32_t e) {
    Eigen::Vector2d a, b;
    elementEnds(e, a, b);
    l1 += std::min(std::abs(b.x() - a.x()), w) + std::min(std::abs(b.y() - a.y()), hgt);
  });
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
  return g;
}

namespace
{
/// Widening of a grid's cells when listing segments (rounding of the cell bounds).
template <class Grid>
double cellMargin(const Grid& g)
{
  return 1e-6 * g.cell_m + 1e-15 * (std::abs(g.x0) + std::abs(g.y0) + (g.rx1 - g.rx0) + (g.ry1 - g.ry0));
}

/// Anonymous pages of memory whose beginning can be handed back to the system while the rest is in use.
class ReleasablePages
{
public:
  explicit ReleasablePages(std::size_t bytes)
    : bytes_(std::max<std::size_t>(bytes, 1))
  {
    data_ = ::mmap(nullptr, bytes_, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (data_ == MAP_FAILED)
      throw std::bad_alloc();
  }
  ~ReleasablePages() { ::munmap(data_, bytes_); }
  ReleasablePages(const ReleasablePages&) = delete;
  ReleasablePages& operator=(const ReleasablePages&) = delete;
  void* data() const { return data_; }
  /// The whole pages of [0, \p bytes) are no longer read: their memory goes back (they would read zero).
  void releaseBelow(std::size_t bytes)
  {
    const std::size_t page = static_cast<std::size_t>(::sysconf(_SC_PAGESIZE));
    const std::size_t end = std::min(bytes, bytes_) / page * page;
    if (end > released_)
    {
      ::madvise(static_cast<char*>(data_) + released_, end - released_, MADV_DONTNEED);
      released_ = end;
    }
  }

private:
  std::size_t bytes_;
  void* data_ = nullptr;
  std::size_t released_ = 0;
};

/// Runs task(1) on \p side (if any) beside task(0) on this thread, and waits for both; the first error is rethrown once
/// both are done (the tasks share the caller's locals).
template <class Task>
void onBothThreads(SideThread* side, const Task& task)
{
  if (!side)
  {
    task(0);
    return;
  }
  side->start([&task] { task(1); });
  try
  {
    task(0);
  }
  catch (...)
  {
    try
    {
      side->wait();
    }
    catch (...)  // the first error is the one reported
    {
    }
    throw;
  }
  side->wait();
}

[[noreturn]] void throwTooLarge()
{
  throw InputError("contour error: actual path too large for the index (more than 2^32 cell entries)");
}
}  // namespace

template <class Each, class F>
void NearestPathIndex::listCells(const Each& each, const Grid& g, F&& f) const
{
  const double margin = cellMargin(g);
  each([&](std::uint32_t e) {
    Eigen::Vector2d a, b;
    elementEnds(e, a, b);
    forEachCell(a, b, g.x0, g.y0, g.cell_m, g.inv_cell, g.nx, g.ny, margin, [&](std::size_t c) { f(e, c); });
  });
}

NearestPathIndex::NearestPathIndex(const PathPoints& path, unsigned threads)
  : path_(&path)
  , path_points_(path.size())
{
  const std::size_t n = path.size();
  if (n > kMaxPoints)
  {
    throw InputError("contour error: actual path of " + std::to_string(n) + " points is too long for the index (max " +
                     std::to_string(kMaxPoints) + ")");
  }
  Box box = Box::empty();
  forEachElement([&](std::uint32_t e) {
    extend(box, e);
    ++indexed_segments_;
  });
  if (indexed_segments_ > 0)
    buildTop(indexed_segments_, box, threads);
}

void NearestPathIndex::buildTop(std::size_t count, const Box& region, unsigned threads)
{
  // The top grid, its cells' ids listed straight from the path (no array of all the ids) by counting sort into pages
  // of their own, handed back to the system as the cells are refined (the parts grow as the lists go).
  const auto each = [this](auto&& f) { forEachElement(f); };
  Grid top = layGrid(each, count, region);
  const std::size_t ncells = static_cast<std::size_t>(top.nx) * top.ny;
  std::unique_ptr<SideThread> side = threads >= 2 && count > kParallelAbove ? std::make_unique<SideThread>() : nullptr;

  // Counted and listed on two threads when there are two, each over its half of the path (the points before `half`,
  // the others): in every cell the first half's ids come first, so the lists are those of one thread, id for id.
  const std::size_t n = path_->size(), half = side ? n / 2 : n;
  const auto eachOfHalf = [this, n, half](int h) {
    return [this, from = h == 0 ? std::size_t{0} : half, to = h == 0 ? half : n](auto&& f) {
      forEachElementIn(from, to, f);
    };
  };
  std::vector<std::size_t> counts[2] = {std::vector<std::size_t>(ncells, 0),
                                        std::vector<std::size_t>(side ? ncells : 0, 0)};
  onBothThreads(side.get(), [&](int h) {
    listCells(eachOfHalf(h), top, [count = counts[h].data()](std::uint32_t, std::size_t c) { ++count[c]; });
  });
  std::vector<std::size_t> start(ncells + 1, 0);
  std::vector<std::size_t> next_id[2] = {std::vector<std::size_t>(ncells), std::vector<std::size_t>(side ? ncells : 0)};
  for (std::size_t c = 0; c < ncells; ++c)
  {
    next_id[0][c] = start[c];
    if (side)
      next_id[1][c] = start[c] + counts[0][c];
    start[c + 1] = start[c] + counts[0][c] + (side ? counts[1][c] : 0);
  }
  if (start[ncells] > std::numeric_limits<std::uint32_t>::max())
    throwTooLarge();
  ReleasablePages sorted(start[ncells] * sizeof(std::uint32_t));
  auto* ids = static_cast<std::uint32_t*>(sorted.data());
  onBothThreads(side.get(), [&](int h) {
    listCells(eachOfHalf(h), top,
              [ids, next = next_id[h].data()](std::uint32_t e, std::size_t c) { ids[next[c]++] = e; });
  });

  // Each cell refined into its own part, in any order, on up to two threads: a part depends on its cell alone. The
  // lists' pages below the first cell not yet done go back to the system.
  std::vector<Part> parts(ncells);
  std::vector<char> done(ncells, 0);
  std::size_t first_pending = 0;
  std::mutex release;
  std::atomic<std::size_t> next{0};
  std::atomic<bool> failed{false};
  const auto work = [&] {
    std::vector<std::uint32_t> cell;
    for (std::size_t c = next++; c < ncells && !failed; c = next++)
    {
      Part& part = parts[c];
      cell.assign(ids + start[c], ids + start[c + 1]);
      if (!cell.empty())
      {
        part.duplicate_budget = 2 * cell.size();
        buildCell(part, cell, top, c, 0);
        part.offsets.shrink_to_fit();  // (its grids are copied into the index's)
        part.items.shrink_to_fit();
      }
      std::lock_guard<std::mutex> lock(release);
      done[c] = 1;
      while (first_pending < ncells && done[first_pending])
        ++first_pending;
      sorted.releaseBelow(start[first_pending] * sizeof(std::uint32_t));
    }
  };
  onBothThreads(side.get(), [&](int) {
    try
    {
      work();
    }
    catch (...)
    {
      failed = true;  // the other thread takes no more cells
      throw;
    }
  });

  // The index keeps the parts (no copy of their arrays): each grid points at its part's offsets and items, a part's
  // grid numbers shifted past those before it; a top cell lists its refinement's grid, or its leaf (moved here).
  std::size_t grids = 1;
  for (const Part& part : parts)
    grids += part.grids.size();
  grids_.reserve(grids);
  grids_.push_back(top);
  top_.offsets.resize(ncells + 1);
  for (std::size_t c = 0; c < ncells; ++c)
  {
    Part& part = parts[c];
    // At most the top lists' total (checked above): a leaf's ids are its list, a refined cell one item.
    top_.offsets[c] = static_cast<std::uint32_t>(top_.items.size());
    largest_leaf_ = std::max(largest_leaf_, part.largest_leaf);
    if (part.items.empty() || !(part.items.front() & kChildFlag))
    {
      top_.items.insert(top_.items.end(), part.items.begin(), part.items.end());
      part = Part{};
      continue;
    }
    const auto grid_base = static_cast<std::uint32_t>(grids_.size());
    for (std::uint32_t& item : part.items)
      if (item & kChildFlag)
        item += grid_base;
    top_.items.push_back(part.items.front());
    for (Grid g : part.grids)
    {
      g.offsets = part.offsets.data() + g.first_offset;
      g.items = part.items.data();
      grids_.push_back(g);
    }
    part.grids = {};
  }
  top_.offsets[ncells] = static_cast<std::uint32_t>(top_.items.size());
  top_.items.shrink_to_fit();
  grids_.front().offsets = top_.offsets.data();
  grids_.front().items = top_.items.data();
  parts_ = std::move(parts);
}

bool NearestPathIndex::buildGrid(Part& part, const std::vector<std::uint32_t>& elements, const Box& region,
                                 int depth) const
{
  const auto each = [&elements](auto&& f) {
    for (std::uint32_t e : elements)
      f(e);
  };
  Grid g = layGrid(each, elements.size(), region);
  const std::size_t ncells = static_cast<std::size_t>(g.nx) * g.ny;
  if (ncells < 2)
    return false;

  // Counting sort, pass 1: ids per cell.
  std::vector<std::uint32_t> start(ncells + 1, 0);
  listCells(each, g, [&](std::uint32_t, std::size_t c) { ++start[c + 1]; });
  std::size_t total = 0, most = 0;
  for (std::size_t c = 0; c < ncells; ++c)
  {
    most = std::max<std::size_t>(most, start[c + 1]);
    total += start[c + 1];
    if (total > std::numeric_limits<std::uint32_t>::max())
      throwTooLarge();
    start[c + 1] = static_cast<std::uint32_t>(total);
  }
  // Refine only if it splits the cell's contents and the duplicates fit the budget.
  const std::size_t extra = total > elements.size() ? total - elements.size() : 0;
  if (most >= elements.size() || extra > part.duplicate_budget)
    return false;
  part.duplicate_budget -= extra;
  // Pass 2: fill.
  std::vector<std::uint32_t> sorted(total);
  {
    std::vector<std::uint32_t> next(start.begin(), start.end() - 1);
    listCells(each, g, [&](std::uint32_t e, std::size_t c) { sorted[next[c]++] = e; });
  }
  g.first_offset = part.offsets.size();
  part.grids.push_back(g);
  part.offsets.resize(part.offsets.size() + ncells + 1);

  std::vector<std::uint32_t> cell;
  for (std::size_t c = 0; c < ncells; ++c)
  {
    const std::size_t here = part.items.size();
    if (here > std::numeric_limits<std::uint32_t>::max())
      throwTooLarge();
    part.offsets[g.first_offset + c] = static_cast<std::uint32_t>(here);
    cell.assign(sorted.begin() + start[c], sorted.begin() + start[c + 1]);
    if (!cell.empty())
      buildCell(part, cell, g, c, depth);
  }
  part.offsets[g.first_offset + ncells] = static_cast<std::uint32_t>(part.items.size());
  return true;
}

void NearestPathIndex::buildCell(Part& part, std::vector<std::uint32_t>& cell, const Grid& g, std::size_t c,
                                 int depth) const
{
  // Refine a crowded cell; if that does not split it, drop repeated segments (a spot at rest) and try again.
  const auto refine = [&]() {
    if (cell.size() <= kRefineAbove || depth >= kMaxDepth)
      return false;
    // The cell's box (widened by the margin) ∩ the box of its segments holds every part of them that lies in this
    // cell: the child grid covers that.
    const double h = g.cell_m, margin = cellMargin(g);
    const std::size_t ci = c % g.nx, cj = c / g.nx;
    Box sub{g.x0 + ci * h - margin, g.y0 + cj * h - margin, g.x0 + (ci + 1) * h + margin, g.y0 + (cj + 1) * h + margin};
    Box ext = Box::empty();
    for (std::uint32_t e : cell)
      extend(ext, e);
    sub.x0 = std::max(sub.x0, ext.x0);
    sub.y0 = std::max(sub.y0, ext.y0);
    sub.x1 = std::min(sub.x1, ext.x1);
    sub.y1 = std::min(sub.y1, ext.y1);
    if (!(sub.x0 <= sub.x1 && sub.y0 <= sub.y1))
      return false;
    part.items.push_back(kChildFlag | static_cast<std::uint32_t>(part.grids.size()));
    if (buildGrid(part, cell, sub, depth + 1))
      return true;
    part.items.pop_back();
    return false;
  };
  if (refine())
    return;
  if (cell.size() > kDeduplicateAbove)
  {
    const std::size_t before = cell.size();
    removeDuplicates(cell);
    if (cell.size() < before && refine())
      return;
  }
  part.largest_leaf = std::max(part.largest_leaf, cell.size());
  part.items.insert(part.items.end(), cell.begin(), cell.end());
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

double NearestPathIndex::leafDistance(const std::uint32_t* begin, const std::uint32_t* end, const Eigen::Vector2d& p,
                                      double best) const
{
  // min over the cell of √(d²) = √(min d²) (√ is monotone and correctly rounded): one root per cell.
  double best2 = std::numeric_limits<double>::infinity();
  for (const std::uint32_t* k = begin; k < end; ++k)
    best2 = std::min(best2, elementDistance(*k, p));
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
        const std::uint32_t* begin = g.items + g.offsets[cell];
        const std::uint32_t* end = g.items + g.offsets[cell + 1];
        if (begin == end || !(*begin & kChildFlag))
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
  const std::uint32_t* begin = g.items + g.offsets[cell];
  const std::uint32_t* end = g.items + g.offsets[cell + 1];
  if (begin == end)
    return;
  if (work)
    ++work->cells_visited;
  if (*begin & kChildFlag)
  {
    search(*begin & ~kChildFlag, p, best, work, hint, within);
    return;
  }
  best = leafDistance(begin, end, p, best);
  if (work)
    work->segments_tested += end - begin;
}

std::size_t NearestPathIndex::memoryBytes() const
{
  const auto arrays = [](const Part& part) {
    return (part.offsets.capacity() + part.items.capacity()) * sizeof(std::uint32_t);
  };
  std::size_t bytes =
      sizeof(*this) + grids_.capacity() * sizeof(Grid) + parts_.capacity() * sizeof(Part) + arrays(top_);
  for (const Part& part : parts_)
    bytes += arrays(part);
  return bytes;
}
}  // namespace scanhead
