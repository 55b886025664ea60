/// \file laser_placement.hpp
/// \brief Laser-on samples off the marked path: what too short a laser-on delay leaves during a
/// jump's settling (SPEC §2.5, THESIS §2.6).
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "scanhead/common/chunk.hpp"
#include "scanhead/job/scan_job.hpp"

namespace scanhead
{
struct LaserPlacementCounts
{
  std::uint64_t laser_on_samples = 0;  ///< samples with power > 0
  std::uint64_t off_path_samples = 0;  ///< of those, the actual spot farther than the tolerance from every mark
  double off_path_energy_j = 0.0;      ///< Σ P·Ts over the off-path samples [J]
  /// largest distance of a laser-on spot to the nearest mark [m], exact at any distance (a ring
  /// search of the grid beyond the 3 × 3 cells); +inf if a laser-on sample came while the job has no mark
  double max_distance_m = 0.0;
};

/// \brief Counts laser-on samples whose actual spot is farther than a tolerance from every MARK
/// segment (and dwell point) of the job. Marks are indexed in a uniform grid of square cells
/// (side c = max(tolerance, 1 mm), doubled until the grid has at most 2^22 cells), so a query
/// costs the segments of the 3 × 3 cells around it.
///
/// Indexing: the grid covers the marks' bounding box with one cell of margin below and at least
/// one above; each MARK segment is registered in every cell that its tolerance neighbourhood
/// (segment ⊕ square of half side tolerance) touches, row by row (tighter than its bounding box
/// for the 45° hatch); a dwell (1-point MARK polyline) is a zero-length segment; JUMP polylines
/// are not marks. Distance point–segment is exact:
/// \f[ d = \left| p - a - t\,(b - a) \right|, \quad t = \mathrm{clamp}\left(\frac{(p - a)\cdot(b - a)}{|b - a|^2}, 0,
/// 1\right). \f] A laser-on sample (power > 0) is off path if d > tolerance_m (SPEC §2.5, THESIS §2.6); its own cell
/// holds every segment within the tolerance, so the on-path test reads one cell. Most samples need no search: with q
/// the last sample searched, L(q) ≤ d(q) a lower bound of its distance (d(q) itself, or what its own cell proves) and
/// s(q) its nearest segment found, the distance d(p) is bounded by |p − s(q)| from above and by L(q) − |p − q| from
/// below (d is 1-Lipschitz); when the bounds settle both the off-path test and the running maximum, the grid is not
/// searched (the counts are those of a full search). Chunk sizes do not change the counts (the state above is carried
/// across chunks).
class LaserPlacement
{
public:
  /// \param[in] job the marks' geometry (speeds and powers do not matter)
  /// \param[in] tolerance_m > 0 [m]
  /// \throws ConfigError if tolerance_m is not finite and > 0 ("laser_placement.tolerance_m")
  /// \throws InputError on a non-finite MARK vertex
  LaserPlacement(const Job& job, double tolerance_m);

  /// \brief Adds the laser-on samples of \p chunk (energy Σ P·period_s over the off-path ones).
  /// \throws NumericalError on a non-finite actual spot of a laser-on sample
  void add(const SpotChunk& chunk);
  const LaserPlacementCounts& counts() const { return counts_; }

  /// \brief Distance from \p point to the nearest mark [m], searching the 3 × 3 cells around it:
  /// exact up to the search reach of one cell side c (every segment within c of the point lies in
  /// those cells); infinity beyond the reach, or if the job has no mark; NaN for a non-finite point.
  double distanceToMarks(const Eigen::Vector2d& point) const;

  double cellSide() const { return cell_m_; }  ///< c [m]

private:
  /// A segment a + t·d, t ∈ [0, 1]; inv_len2 = 1/|d|² (0 for a dwell point).
  struct Segment
  {
    double ax, ay, dx, dy, inv_len2;
  };
  /// Smallest squared distance from (px, py) to the segments of the cells [i0, i1] × [j0, j1]
  /// (already clipped to the grid), folded into \p best [m²] and its segment \p best_id.
  void searchCells(double px, double py, long i0, long i1, long j0, long j1, double& best,
                   std::uint32_t& best_id) const;
  /// Exact distance to the nearest mark [m], by rings of cells around the point; \p id its segment.
  double exactDistance(const Eigen::Vector2d& point, std::uint32_t& id) const;

  double tolerance_m_;
  LaserPlacementCounts counts_;
  double cell_m_ = 1e-3;                                     ///< cell side c [m]
  Eigen::Vector2d grid_origin_m_ = Eigen::Vector2d::Zero();  ///< lower-left corner of cell (0, 0) [m]
  long nx_ = 0, ny_ = 0;                                     ///< cells per row / column (0: no mark)
  std::vector<Segment> segments_;
  std::vector<std::size_t> cell_start_;       ///< cell (i, j) = j·nx + i holds cell_segments_[start[c], start[c+1])
  std::vector<std::uint32_t> cell_segments_;  ///< segment indices, cell by cell
  // The last searched laser-on sample (bounds for the next ones), carried across chunks.
  bool has_last_ = false;
  Eigen::Vector2d last_point_m_ = Eigen::Vector2d::Zero();
  double last_distance_m_ = 0.0;
  std::uint32_t last_segment_ = 0;
};
}  // namespace scanhead
