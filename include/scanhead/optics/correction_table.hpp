/// \file correction_table.hpp
/// \brief The NC's correction table: joint angles on a grid of work-plane nodes, interpolated
/// (SPEC §2.2, THESIS §2.3.2.2: 65 × 65 nodes over the field, bilinear).
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <string>
#include <vector>

#include "scanhead/optics/optical_model.hpp"

namespace scanhead
{
enum class TableInterpolation
{
  Bilinear,  ///< the four surrounding nodes (THESIS)
  Bicubic    ///< higher order (see correction_table.cpp for the scheme), < 1 µm at 65 × 65
};

/// \brief "bilinear" | "bicubic". \throws ConfigError naming \p field and listing the choices
TableInterpolation parseTableInterpolation(const std::string& text, const std::string& field);

/// \brief Joint angles q(x, y) at nodes x_i = −h + i·2h/(n−1), y_j likewise (i, j = 0..n−1),
/// plus whatever the bicubic scheme needs, and their interpolation.
class CorrectionTable
{
public:
  /// \brief Solves the inverse model (Newton, OpticalModel::inverse) at every node.
  /// \param[in] nodes          n >= 2 per axis
  /// \param[in] half_width_m   h > 0: the table covers [−h, h]² [m]
  /// \throws ConfigError on bad n or h; NumericalError naming a node the optics cannot reach
  static CorrectionTable build(const OpticalModel& optics, int nodes, double half_width_m);

  /// \brief Reads a table file (format in correction_table.cpp's header comment).
  /// \throws InputError naming the file, the line and what is wrong
  static CorrectionTable load(const std::string& path);

  /// \brief Writes the table file atomically (temporary file + rename). \throws InputError
  void save(const std::string& path) const;

  /// \brief Interpolated joint angles at \p spot_m [rad].
  /// \throws NumericalError if the point lies outside [−h, h]² (names the point)
  Eigen::Vector2d joints(const Eigen::Vector2d& spot_m, TableInterpolation interpolation) const;

  int nodes() const { return nodes_; }
  double halfWidth() const { return half_width_m_; }

private:
  /// One node: angles and their derivatives w.r.t. the spot (one 64-byte cache line).
  struct Node
  {
    double q[2] = { 0.0, 0.0 };     ///< (q_x, q_y) [rad]
    double q_x[2] = { 0.0, 0.0 };   ///< ∂q/∂x [rad/m] (exact: first column of J⁻¹)
    double q_y[2] = { 0.0, 0.0 };   ///< ∂q/∂y [rad/m] (exact: second column of J⁻¹)
    double q_xy[2] = { 0.0, 0.0 };  ///< ∂²q/∂x∂y [rad/m²] (differenced over the grid)
  };

  /// Sets n, h, the spacing and n² zero nodes.
  void setShape(int nodes, double half_width_m);
  std::size_t index(int i, int j) const
  {
    return static_cast<std::size_t>(j) * static_cast<std::size_t>(nodes_) + static_cast<std::size_t>(i);
  }

  int nodes_ = 0;
  double half_width_m_ = 0.0;
  double spacing_m_ = 0.0;    ///< Δ = 2h / (n − 1) [m]
  double inv_spacing_ = 0.0;  ///< 1 / Δ [1/m]
  std::vector<Node> node_;    ///< row-major: index j·n + i (j: y, i: x)
};

/// \brief Interpolation error of a table against the optics, over a dense probe grid.
struct TableErrorReport
{
  double max_error_m = 0.0;   ///< max |h(q_table(x)) − x| over the probes [m], h the direct model
  double rms_error_m = 0.0;   ///< RMS of the same [m]
  Eigen::Vector2d worst_point_m = Eigen::Vector2d::Zero();  ///< where the max is [m]
  int probes_per_axis = 0;    ///< probes x_k = −h + k·2h/(p−1) in each axis
};

/// \brief Error of \p table with \p interpolation: each probe x goes through the table, then the
/// direct model: e = |h(q_table(x)) − x| at the plane. \param probes_per_axis p >= 2
TableErrorReport measureTableError(const CorrectionTable& table, TableInterpolation interpolation,
                                   const OpticalModel& optics, int probes_per_axis);
}  // namespace scanhead
