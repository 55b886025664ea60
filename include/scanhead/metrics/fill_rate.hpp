/// \file fill_rate.hpp
/// \brief Fill rate of a layer (THESIS §2.5, Fig. 2.73; SPEC §5): the share of the cells that the
/// commanded marks reach which the actual spot also reaches.
///
/// THESIS: "the surface to fill is discretised with a step in x and y equal to the laser spot
/// diameter; the discrete cells reached by the marking are counted and the fill rate is the ratio of
/// the cells reached to the total number of cells". General form used here (any job, exactly 100 %
/// for a perfect machine):
///  - a grid of square cells of pitch d (the spot diameter), cell (c, r) covering
///    [x0 + c·d, x0 + (c+1)·d] × [y0 + r·d, y0 + (r+1)·d], (x0, y0) = min_corner; row 0 at the lowest y;
///  - the spot at p is the disc of radius w = d/2; a laser-on path (the polyline through consecutive
///    laser-on points, or a single point) reaches cell C when
///    \f[ \operatorname{dist}(\text{path}, C) < w \f]
///    (distance between the path and the closed square; strict, so a spot centred in a cell does not
///    reach its neighbours);
///  - to fill = cells reached by the COMMANDED path with the laser on; reached = cells reached by the
///    ACTUAL spot with the laser on; fill rate = |reached ∩ to fill| / |to fill|.
///
/// Two consecutive points are joined (the segment between them marks) when both have the laser on
/// and no break was inserted between them. Each segment is cut into sub-segments of at most w/2
/// (so each touches at most 3 × 3 cells) and every candidate cell is tested exactly against the
/// sub-segment, so the result is the continuous sweep of the disc: a fast, sparsely sampled spot
/// leaves no hole, and the answer does not depend on how densely a straight segment is sampled.
///
/// Storage: 2 bits per cell, dense over the grid (a 350 mm field at 70 µm: 5000² cells, 6.25 MB),
/// at most 2^31 cells. The counts are kept up to date as points arrive, in any interleaving of the
/// commanded and actual streams.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace scanhead
{
class FillRateGrid
{
public:
  static constexpr std::uint8_t kToFill = 1;   ///< cellState bit 0: reached by the commanded marks
  static constexpr std::uint8_t kReached = 2;  ///< cellState bit 1: reached by the actual spot

  /// \brief A grid covering [min_corner, max_corner]: width = max(1, ceil((max.x − min.x)/d)) cells
  /// (ceil with a 1e-9 cell tolerance), same in y. Pass the job's bounds widened by at least the
  /// spot diameter plus the expected path errors: a laser-on point whose disc reaches beyond the
  /// grid is counted in pointsOutside() (the cells beyond are not recorded).
  /// \param[in] min_corner lower-left corner, the origin of the cells [m]
  /// \param[in] max_corner upper-right corner [m]
  /// \param[in] spot_diameter_m cell pitch d = spot diameter [m]
  /// \throws ConfigError if spot_diameter_m is not finite and > 0, or the grid would exceed 2^31 cells
  /// \throws InputError if the corners are not finite or max < min
  FillRateGrid(const Eigen::Vector2d& min_corner, const Eigen::Vector2d& max_corner, double spot_diameter_m);

  /// \brief Next point of the commanded path [m], with the laser state the CAM commands there.
  /// \throws InputError if \p p is not finite (the grid is unchanged)
  void addCommanded(const Eigen::Vector2d& p, bool laser_on);
  /// \brief Next point of the actual spot path [m], with the actual laser state.
  /// \throws InputError if \p p is not finite (the grid is unchanged)
  void addActual(const Eigen::Vector2d& p, bool laser_on);
  /// \brief The next commanded point is not joined to the previous one.
  void breakCommanded();
  /// \brief The next actual point is not joined to the previous one (e.g. a gap in the stream).
  void breakActual();
  /// \brief Clears every cell, count and pending point.
  void reset();

  std::uint64_t cellsToFill() const { return to_fill_; }
  /// \brief Cells reached by the actual spot among those to fill.
  std::uint64_t cellsReached() const { return reached_in_; }
  /// \brief Cells reached by the actual spot but not to fill (marking beside the commanded marks).
  std::uint64_t cellsReachedOutside() const { return reached_out_; }
  /// \brief cellsReached() / cellsToFill(); NaN when there is nothing to fill.
  double fillRate() const;

  /// \brief Laser-on points (commanded + actual) whose disc reaches beyond the grid.
  std::uint64_t pointsOutside() const { return commanded_.outside + actual_.outside; }
  std::uint64_t commandedPointsOutside() const { return commanded_.outside; }
  std::uint64_t actualPointsOutside() const { return actual_.outside; }

  /// \brief Bytes held by the grid (the cell bits and this object).
  std::size_t memoryBytes() const;

  int width() const { return width_; }
  int height() const { return height_; }
  double pitch() const { return pitch_; }                    ///< d [m]
  const Eigen::Vector2d& origin() const { return origin_; }  ///< lower-left corner of cell (0, 0) [m]
  /// \brief Bit 0 (kToFill): to fill; bit 1 (kReached): reached by the actual spot. Row 0 is at the
  /// lowest y (flip it for an image whose row 0 is the top).
  /// \throws std::out_of_range if (col, row) is not a cell of the grid
  std::uint8_t cellState(int col, int row) const;

private:
  struct PathState
  {
    Eigen::Vector2d last = Eigen::Vector2d::Zero();  ///< in cell units, relative to origin_
    bool joinable = false;                           ///< last point exists, had the laser on, no break since
    std::uint64_t outside = 0;
  };

  void add(PathState& state, const Eigen::Vector2d& p, bool laser_on, std::uint8_t bit, const char* which);
  void markSegment(Eigen::Vector2d a, Eigen::Vector2d b, std::uint8_t bit);
  void markSubSegment(const Eigen::Vector2d& a, const Eigen::Vector2d& b, std::uint8_t bit);
  void setBit(std::size_t cell, std::uint8_t bit);

  Eigen::Vector2d origin_;
  double pitch_;
  int width_ = 0, height_ = 0;
  std::vector<std::uint64_t> bits_;  ///< 32 cells per word, cell i at bits 2(i mod 32), 2(i mod 32)+1
  std::uint64_t to_fill_ = 0, reached_in_ = 0, reached_out_ = 0;
  PathState commanded_, actual_;
};
}  // namespace scanhead
