/// \file nearest_path_index.hpp
/// \brief Grid index (uniform grids in CSR form, refined where crowded) over the segments of a
/// PathPoints, for exact nearest-path distance queries: contour error definition (a) (contour_error.hpp).
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

#include "scanhead/metrics/path_points.hpp"

namespace scanhead
{
/// \brief Work done by one NearestPathIndex query (to check that it stays bounded; not timing).
struct NearestPathWork
{
  std::uint64_t cells_visited = 0;    ///< grid cells whose contents were read
  std::uint64_t segments_tested = 0;  ///< point-to-segment distances computed
};

/// \brief The leaf cell that held the last query's point (NearestPathIndex::distance): consecutive points of a path
/// fall in the same leaf, and a point whose bound disc lies inside it needs that leaf alone. One per thread of queries
/// and per index.
struct NearestPathHint
{
  /// The leaf cell's box clipped to the regions of its grid and of that grid's ancestors, where the leaf lists every
  /// segment that crosses it [m] (empty: no leaf yet).
  double x0 = 0.0, y0 = 0.0, x1 = -1.0, y1 = -1.0;
  const std::uint32_t* begin = nullptr;  ///< its segment ids in the index
  const std::uint32_t* end = nullptr;
};

/// \brief Spatial index over the segments of a PathPoints for exact nearest-path distance queries
/// (definition (a)).
///
/// Layout: uniform grids in CSR form (per grid, cell offsets into one array of segment ids), built
/// by counting sort. The top grid covers the path's bounding box with about n/4 cells, at most
/// ~4096; a cell holding more than 12 segments is itself refined by a uniform grid over the box of
/// its contents (recursively, at most 10 levels), so that a dense hatch inside a sparsely covered
/// 350 mm field still ends with a few segments per leaf cell. Cell sizes come from the region's
/// box and the segments' lengths (a cell is at least a third of the mean segment length, so a
/// segment lands in a few cells). A segment is listed in every cell it crosses (conservative
/// supercover, with a margin of 1e-6 cell).
/// - Spot at rest: zero-length segments that repeat the previous point are not indexed (they add
///   no geometry), and a crowded cell that refining does not split keeps identical stored segments
///   once, so an exact dwell costs one segment per query and a dwell jittering over 3 float values
///   per axis about ten. Limit: a dwell jittering over many float values (e.g. ±6 ulp) leaves a leaf
///   of all its distinct segments (~1000), tested by every query near it (exact, slower).
/// - Memory O(n): refinements may duplicate at most 2 ids per id of the top grid (beyond that, cells stay
///   unrefined: slower, still exact); 6–18 B per point on hatches (8 at 1e7).
/// - Build O(n · levels), on up to two threads: the top grid's lists are counted and filled over the two halves of the
///   path (the first half's ids first in every cell), and its cells are refined independently (each with its own
///   duplicate budget, 2 ids per id it lists), so the index is the same whatever the thread count. Transient memory:
///   the top grid's cell lists and the refined parts (about twice the final index), never the whole path's ids twice
///   more (the THESIS layer: 30.5 M points).
/// - Query: ring search from the cell of p, stopped once the distance from p
///   to the cells outside the rings read so far is ≥ the best distance found; a cell (or a refined
///   cell's box) is read only if its box is nearer than the best distance found. Measured: ~7
///   segments per query near a 1e7-point hatch, ~15–50 for points anywhere in a 350 mm field.
///   The result is exact: the minimum of the same point-segment distances as the brute force, up
///   to the rounding of the box bounds (≈ 1e-16 m).
///
/// The index keeps a pointer to \p path: the path must outlive it. Points appended after the
/// build are not indexed (the indexed ones are unaffected).
class NearestPathIndex
{
public:
  /// \param[in] threads 2 or more: the top grid's cells are refined on two threads (same index as one)
  /// \throws InputError if the path has more than 2^30 points (ids are 30-bit)
  explicit NearestPathIndex(const PathPoints& path, unsigned threads = 1);
  NearestPathIndex(const NearestPathIndex&) = delete;  // grids point into its own arrays
  NearestPathIndex& operator=(const NearestPathIndex&) = delete;
  NearestPathIndex(NearestPathIndex&&) = default;  // the arrays move, their contents stay put
  NearestPathIndex& operator=(NearestPathIndex&&) = default;

  /// \brief Minimum distance from \p p to the indexed path [m], capped at \p upper_bound_m:
  /// returns min(exact distance, upper_bound_m). An empty path returns upper_bound_m.
  /// \param[in] upper_bound_m a known upper bound (e.g. the same-instant error) prunes the search
  /// \param[out] work if not null, incremented by the work done
  /// \param[in,out] hint if not null: the leaf cell of the previous query. When the disc of radius upper_bound_m
  ///                 around \p p lies inside that cell, only its segments are read: every segment nearer than
  ///                 the bound meets the disc, so crosses the cell, so is listed in it (supercover), and the result
  ///                 is the one of the full search bit for bit (a minimum of the same distances). Else the full
  ///                 search, which records the leaf holding \p p.
  /// \throws InputError if \p p is not finite or \p upper_bound_m is negative or NaN
  double distance(const Eigen::Vector2d& p, double upper_bound_m = std::numeric_limits<double>::infinity(),
                  NearestPathWork* work = nullptr, NearestPathHint* hint = nullptr) const;

  std::size_t indexedSegments() const { return indexed_segments_; }  ///< after dropping repeats
  std::size_t pathPoints() const { return path_points_; }            ///< points indexed
  std::size_t gridCount() const { return grids_.size(); }            ///< top grid + refinements
  std::size_t largestLeaf() const { return largest_leaf_; }          ///< most segments in one leaf cell
  std::size_t memoryBytes() const;                                   ///< index only, not the path

private:
  struct Grid
  {
    double x0 = 0, y0 = 0;  ///< lower-left corner of cell (0, 0) [m]
    double cell_m = 1, inv_cell = 1;
    std::uint32_t nx = 1, ny = 1;
    double rx0 = 0, ry0 = 0, rx1 = 0, ry1 = 0;  ///< box holding the parts of the segments it indexes [m]
    std::size_t first_offset = 0;               ///< index of cell 0's offset in its part's offsets
    const std::uint32_t* offsets = nullptr;     ///< nx·ny + 1 offsets into items (set once its part is done)
    const std::uint32_t* items = nullptr;       ///< its part's items
  };
  struct Box;
  /// \brief A top cell's refinement (its grids numbered from 0 until the index takes them), or the top grid itself.
  struct Part
  {
    std::vector<Grid> grids;
    std::vector<std::uint32_t> offsets;  ///< per grid: nx·ny + 1 offsets into items
    std::vector<std::uint32_t> items;    ///< segment ids (bit 30: zero length) or bit 31 | child grid
    std::size_t largest_leaf = 0;
    std::size_t duplicate_budget = 0;  ///< ids its refinements may still add beyond their input
  };

  /// \brief Calls f(element) for each indexed element of the path (segment i → i+1, or the isolated point i).
  template <class F>
  void forEachElement(F&& f) const;
  /// \brief forEachElement over the path's points [from, to) (a segment i → i+1 is point i's element).
  template <class F>
  void forEachElementIn(std::size_t from, std::size_t to, F&& f) const;
  /// \brief The grid over \p region sized for \p count elements (each(f) calls f on each).
  template <class Each>
  Grid layGrid(const Each& each, std::size_t count, const Box& region) const;
  /// \brief Calls f(element, cell) for every cell of \p g that lists the element, for each element each(f) gives.
  template <class Each, class F>
  void listCells(const Each& each, const Grid& g, F&& f) const;
  void buildTop(std::size_t count, const Box& region, unsigned threads);
  /// \brief Refines a cell into \p part (false: no refinement splits it or fits the budget; nothing added).
  bool buildGrid(Part& part, const std::vector<std::uint32_t>& elements, const Box& region, int depth) const;
  /// \brief Appends cell \p c of \p g (a grid at \p depth) to \p part: a child grid, or a leaf of \p cell.
  void buildCell(Part& part, std::vector<std::uint32_t>& cell, const Grid& g, std::size_t c, int depth) const;
  void removeDuplicates(std::vector<std::uint32_t>& elements) const;
  /// \param[in] within the intersection of the regions of the grid's ancestors (for the hint's box)
  void search(std::size_t grid, const Eigen::Vector2d& p, double& best, NearestPathWork* work, NearestPathHint* hint,
              const Box& within) const;
  void visitCell(const Grid& g, std::size_t cell, const Eigen::Vector2d& p, double& best, NearestPathWork* work,
                 NearestPathHint* hint, const Box& within) const;
  /// \brief min(best, distance to the segments [begin, end)).
  double leafDistance(const std::uint32_t* begin, const std::uint32_t* end, const Eigen::Vector2d& p,
                      double best) const;
  double elementDistance(std::uint32_t element, const Eigen::Vector2d& p) const;  ///< squared [m²]
  void elementEnds(std::uint32_t element, Eigen::Vector2d& a, Eigen::Vector2d& b) const;
  void extend(Box& box, std::uint32_t element) const;  ///< \p box grown to hold the element

  const PathPoints* path_;
  std::size_t path_points_ = 0;
  std::size_t indexed_segments_ = 0;
  std::size_t largest_leaf_ = 0;
  std::vector<Grid> grids_;  ///< the top grid, then each part's grids in cell order
  Part top_;                 ///< the top grid's offsets and items (a refined cell: bit 31 | its grid)
  std::vector<Part> parts_;  ///< per top cell: the offsets and items of its grids
};
}  // namespace scanhead
