/// \file contour_error.hpp
/// \brief Contour error between a commanded path and the actual spot path, both definitions of
/// SPEC §5: (a) nearest path (NC paper) and (b) same instant (THESIS §2.5.3.1), with their statistics.
///
/// Both paths are sampled every Ts. For commanded point c_k:
/// - (a) nearest path: \f[ e_a(k) = \min_{j} d(c_k, [p_j, p_{j+1}]) \f] over every segment of the
///   actual path (NearestPathIndex: exact, about O(1) per query on scan paths);
/// - (b) same instant (Duong et al. 2016, linear interpolation): with j = j(k) the actual sample of
///   the same instant (delay-compensated, j = k + lag, given by the caller),
///   \f[ e_b(k) = \min\big(d(c_k, [p_{j-1}, p_j]),\ d(c_k, [p_j, p_{j+1}])\big) \f]
///   over the segments that exist (sameInstantDistance: O(1), streaming).
///
/// d is the exact point-to-segment distance (segment_distance.hpp). Since the segments of (b) are
/// part of the path, e_a(k) ≤ e_b(k) always; e_b is a valid upper bound hint for e_a.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

namespace scanhead
{
/// \brief The actual path, stored compactly: float32 x, y relative to a double origin
/// (8 B/point, plus 1 bit/point for the breaks), appended in order.
///
/// Point i joins point i + 1 by a segment unless breakPath() was called between them (a stream
/// gap, a new layer): no segment crosses a break. A point joined to neither neighbour is an
/// isolated point of the path (distance to it counts).
///
/// Resolution: a coordinate u = p − origin is rounded to the nearest float, an error of at most
/// half an ulp, 2^(⌊log2|u|⌋ − 24): 1.5e-8 m for |u| in [0.25, 0.5) m (ulp ≈ 3e-8 m at 0.35 m),
/// 7.5e-9 m for [0.125, 0.25) m. Put the origin at the field centre so that |u| ≤ 0.25 m on a
/// 350 mm field. Every computation of this file reads the stored points back through point(),
/// so all methods (and brute-force checks) see the same geometry.
class PathPoints
{
public:
  /// \param[in] origin reference the points are stored relative to [m]
  /// \throws InputError if \p origin is not finite
  explicit PathPoints(const Eigen::Vector2d& origin = Eigen::Vector2d::Zero());

  /// \brief Reserves room for \p points points (memory only).
  void reserve(std::size_t points);

  /// \brief Appends \p p [m], joined to the previous point unless a break precedes it.
  /// \throws InputError if \p p is not finite or p − origin overflows a float; the message names
  ///   the index the point would have had ("contour error: actual path point 12 is not finite").
  void add(const Eigen::Vector2d& p);

  /// \brief No segment joins the last point to the next one added (no-op on an empty path).
  void breakPath();

  std::size_t size() const { return xy_.size() / 2; }
  bool empty() const { return xy_.empty(); }
  const Eigen::Vector2d& origin() const { return origin_; }

  /// \brief Stored point i [m]: origin + the float offset, exactly as every method sees it.
  /// \pre i < size()
  Eigen::Vector2d point(std::size_t i) const
  {
    return origin_ + Eigen::Vector2d(static_cast<double>(xy_[2 * i]), static_cast<double>(xy_[2 * i + 1]));
  }

  /// \brief True if a segment joins point i to point i + 1 (false for the last point and beyond).
  bool joinsNext(std::size_t i) const
  {
    return i + 1 < size() && ((break_after_[i >> 6] >> (i & 63)) & 1u) == 0;
  }

  /// \brief Bytes held (capacity of the arrays plus the object).
  std::size_t memoryBytes() const;

private:
  Eigen::Vector2d origin_;
  std::vector<float> xy_;                   ///< x0, y0, x1, y1, … relative to origin_ [m]
  std::vector<std::uint64_t> break_after_;  ///< bit i: no segment from point i to i + 1
};

/// \brief Work done by one NearestPathIndex query (to check that it stays bounded; not timing).
struct NearestPathWork
{
  std::uint64_t cells_visited = 0;    ///< grid cells whose contents were read
  std::uint64_t segments_tested = 0;  ///< point-to-segment distances computed
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
/// - Memory O(n): refinements may duplicate at most 2 ids per indexed segment in total (beyond
///   that, cells stay unrefined: slower, still exact); 6–18 B per point on hatches (8 at 1e7).
/// - Build O(n · levels); query: ring search from the cell of p, stopped once the distance from p
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
  /// \throws InputError if the path has more than 2^30 points (ids are 30-bit)
  explicit NearestPathIndex(const PathPoints& path);

  /// \brief Minimum distance from \p p to the indexed path [m], capped at \p upper_bound_m:
  /// returns min(exact distance, upper_bound_m). An empty path returns upper_bound_m.
  /// \param[in] upper_bound_m a known upper bound (e.g. the same-instant error) prunes the search
  /// \param[out] work if not null, incremented by the work done
  /// \throws InputError if \p p is not finite or \p upper_bound_m is negative or NaN
  double distance(const Eigen::Vector2d& p, double upper_bound_m = std::numeric_limits<double>::infinity(),
                  NearestPathWork* work = nullptr) const;

  std::size_t indexedSegments() const { return indexed_segments_; }  ///< after dropping repeats
  std::size_t pathPoints() const { return path_points_; }            ///< points indexed
  std::size_t gridCount() const { return grids_.size(); }            ///< top grid + refinements
  std::size_t largestLeaf() const { return largest_leaf_; }          ///< most segments in one leaf cell
  std::size_t memoryBytes() const;                                   ///< index only, not the path

private:
  struct Grid
  {
    double x0 = 0, y0 = 0;      ///< lower-left corner of cell (0, 0) [m]
    double cell_m = 1, inv_cell = 1;
    std::uint32_t nx = 1, ny = 1;
    double rx0 = 0, ry0 = 0, rx1 = 0, ry1 = 0;  ///< box holding the parts of the segments it indexes [m]
    std::size_t first_offset = 0;               ///< index of cell 0's offset in offsets_
  };
  struct Box;

  bool buildGrid(const std::vector<std::uint32_t>& elements, const Box& region, int depth, bool top);
  void removeDuplicates(std::vector<std::uint32_t>& elements) const;
  void emitLeaf(const std::vector<std::uint32_t>& elements);
  void search(std::size_t grid, const Eigen::Vector2d& p, double& best, NearestPathWork* work) const;
  void visitCell(const Grid& g, std::size_t cell, const Eigen::Vector2d& p, double& best, NearestPathWork* work) const;
  double elementDistance(std::uint32_t element, const Eigen::Vector2d& p) const;
  void elementEnds(std::uint32_t element, Eigen::Vector2d& a, Eigen::Vector2d& b) const;

  const PathPoints* path_;
  std::size_t path_points_ = 0;
  std::size_t indexed_segments_ = 0;
  std::size_t largest_leaf_ = 0;
  std::size_t duplicate_budget_ = 0;   ///< ids refinements may still add beyond their input
  std::vector<Grid> grids_;
  std::vector<std::uint32_t> offsets_;  ///< per grid: nx·ny + 1 offsets into items_
  std::vector<std::uint32_t> items_;    ///< segment ids (bit 30: zero length) or bit 31 | child grid
};

/// \brief Definition (a) by brute force: minimum over every segment (and isolated point) of
/// \p path of the distance to \p p [m]; +infinity for an empty path. O(n), for tests.
double nearestPathDistanceBruteForce(const PathPoints& path, const Eigen::Vector2d& p);

/// \brief Definition (b): distance from the commanded point \p p to the actual segments adjacent
/// to the same-instant sample \p j (j−1→j and j→j+1, those that exist; the point p_j itself if
/// neither does) [m]. The orthogonal projection is clamped to each segment (exact point-segment
/// distance). O(1).
/// \throws InputError if \p j ≥ path.size() or \p p is not finite
double sameInstantDistance(const PathPoints& path, std::size_t j, const Eigen::Vector2d& p);

/// \brief Running statistics of contour errors: count, mean, max, share under a limit, and a fixed
/// histogram of 1 µm bins over [0, 100) µm plus an overflow bin.
///
/// Deterministic and mergeable exactly: each error is quantised to 1 pm (1e-12 m) and the sum is
/// kept as a 128-bit integer, so merge(a, b) gives bit for bit what adding all values one by one
/// gives, in any order. Bin k holds the errors whose quantised value q satisfies k µm ≤ q <
/// (k+1) µm; "under L" means q < L (THESIS: shares under 10, 20, 30 µm).
class ContourErrorStats
{
public:
  static constexpr double kBinWidth_m = 1e-6;  ///< histogram bin [m]
  static constexpr std::size_t kBins = 100;    ///< bins below the overflow bin
  static constexpr double kMaxError_m = 1e3;   ///< larger errors are rejected (not a contour error)

  /// \throws NumericalError if \p error_m is NaN, negative or above kMaxError_m (names the value)
  void add(double error_m);

  /// \brief Adds all values of \p other (same result as adding them one by one).
  void merge(const ContourErrorStats& other);

  std::uint64_t count() const { return count_; }
  double mean() const;  ///< [m]; NaN when empty (quantised to 1 pm)
  double max() const;   ///< [m]; NaN when empty (exact, not quantised)

  /// \brief Number of errors under \p limit_m, a multiple of kBinWidth_m in [0, kBins·kBinWidth_m].
  /// \throws InputError for any other limit (the histogram cannot answer it exactly)
  std::uint64_t countUnder(double limit_m) const;

  /// \brief countUnder(limit_m) / count(); NaN when empty.
  double shareUnder(double limit_m) const;

  /// \brief Count in bin \p bin (bin kBins is the overflow: errors ≥ 100 µm).
  /// \throws InputError if \p bin > kBins
  std::uint64_t binCount(std::size_t bin) const;

  /// \brief Upper bound of the \p fraction quantile, 1 µm resolution: the upper edge of the bin
  /// holding the ⌈fraction·count⌉-th smallest error, capped at max() (max() in the overflow bin).
  /// NaN when empty. \throws InputError if \p fraction is outside [0, 1]
  double quantileUpperBound(double fraction) const;

  bool operator==(const ContourErrorStats& other) const;
  bool operator!=(const ContourErrorStats& other) const { return !(*this == other); }

private:
  std::uint64_t count_ = 0;
  std::uint64_t sum_pm_low_ = 0;   ///< Σ quantised errors [pm], low 64 bits
  std::uint64_t sum_pm_high_ = 0;  ///< high 64 bits
  double max_m_ = 0.0;
  std::array<std::uint64_t, kBins + 1> bins_{};
};
}  // namespace scanhead
