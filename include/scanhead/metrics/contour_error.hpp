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
///
/// The path store is PathPoints (path_points.hpp), the index of definition (a) NearestPathIndex
/// (nearest_path_index.hpp); both are included here.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>

#include "scanhead/metrics/nearest_path_index.hpp"
#include "scanhead/metrics/path_points.hpp"

namespace scanhead
{
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
///
/// Not common/histogram.hpp's Histogram, on purpose: that one bins the unrounded value against
/// double edges (0.9999996 µm falls in bin 0 there, bin 1 here), holds x = hi in its last bin (100 µm
/// is overflow here), keeps a compensated double sum (mean differs in the last digits and is not
/// order-independent), interpolates quantiles within a bin (here: upper bin edge capped at max()),
/// and counts NaN or negative values instead of rejecting them. metrics.yaml prints these figures
/// with 17 digits, so swapping would change it.
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
