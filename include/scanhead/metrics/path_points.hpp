/// \file path_points.hpp
/// \brief The actual spot path for the contour error (contour_error.hpp): float offsets from a double
/// origin, with breaks, read back through one accessor so that every method sees the same geometry.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
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
/// 350 mm field. Every computation of the contour error (contour_error.hpp,
/// nearest_path_index.hpp) reads the stored points back through point(), so all methods (and
/// brute-force checks) see the same geometry.
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
  bool joinsNext(std::size_t i) const { return i + 1 < size() && ((break_after_[i >> 6] >> (i & 63)) & 1u) == 0; }

  /// \brief Bytes held (capacity of the arrays plus the object).
  std::size_t memoryBytes() const;

private:
  Eigen::Vector2d origin_;
  std::vector<float> xy_;                   ///< x0, y0, x1, y1, … relative to origin_ [m]
  std::vector<std::uint64_t> break_after_;  ///< bit i: no segment from point i to i + 1
};
}  // namespace scanhead
