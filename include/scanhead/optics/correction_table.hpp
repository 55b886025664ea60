/// \file correction_table.hpp
/// \brief The NC's correction table: joint angles on a grid of work-plane nodes, interpolated
/// (SPEC §2.2, THESIS §2.3.2.2: 65 × 65 nodes over the field, bilinear).
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <iosfwd>
#include <string>
#include <vector>

#include "scanhead/optics/optical_model.hpp"

namespace scanhead
{
enum class TableInterpolation
{
  Bilinear,  ///< the four surrounding nodes (THESIS)
  Bicubic    ///< Hermite bicubic (scheme on CorrectionTable), < 1 µm at 65 × 65
};

/// \brief "bilinear" | "bicubic". \throws ConfigError naming \p field and listing the choices
TableInterpolation parseTableInterpolation(const std::string& text, const std::string& field);

/// \brief Joint angles q(x, y) at nodes x_i = −h + i·2h/(n−1), y_j likewise (i, j = 0..n−1),
/// plus whatever the bicubic scheme needs, and their interpolation.
///
/// \details Nodes: \f$x_i = -h + i\Delta\f$, \f$y_j = -h + j\Delta\f$, \f$\Delta = 2h/(n-1)\f$,
/// i, j = 0..n−1. Each node holds the joint angles \f$q = h^{-1}(x)\f$ (Newton,
/// OpticalModel::inverse, warm-started from the previous node) and, for the bicubic scheme, the
/// derivatives \f$q_x = \partial q/\partial x\f$, \f$q_y = \partial q/\partial y\f$ and
/// \f$q_{xy} = \partial^2 q/\partial x \partial y\f$.
///
/// \par Bilinear (THESIS §2.3.2.2)
/// The four surrounding nodes, weights \f$(1-u)(1-v)\f$, \f$u(1-v)\f$, \f$(1-u)v\f$, \f$uv\f$ with
/// \f$u = (x - x_i)/\Delta\f$, \f$v = (y - y_j)/\Delta\f$.
///
/// \par Bicubic
/// Hermite bicubic patch per cell, exact for bicubic polynomials:
/// \f[ q(u, v) = \sum_{a, b \in \{0, 1\}} \phi_a(u)\phi_b(v)\,q_{ab}
///     + \Delta\,\psi_a(u)\phi_b(v)\,q_{x,ab} + \Delta\,\phi_a(u)\psi_b(v)\,q_{y,ab}
///     + \Delta^2\,\psi_a(u)\psi_b(v)\,q_{xy,ab} \f]
/// with \f$\phi_0 = 1 - 3u^2 + 2u^3\f$, \f$\phi_1 = 3u^2 - 2u^3\f$, \f$\psi_0 = u - 2u^2 + u^3\f$,
/// \f$\psi_1 = u^3 - u^2\f$. The first derivatives are exact: \f$[q_x\ q_y] = J(q)^{-1}\f$ with
/// \f$J = \partial\,\mathrm{spot}/\partial q\f$ from OpticalModel::jacobian (the inverse function
/// theorem). The cross derivative \f$q_{xy}\f$ is the average of the central differences of
/// \f$q_x\f$ along y and of \f$q_y\f$ along x over one node spacing (second-order one-sided
/// differences on the border; first-order when n = 2): its \f$O(\Delta^2)\f$ error enters with a
/// \f$\Delta^2\f$ weight, so the patch stays \f$O(\Delta^4)\f$. Chosen over Catmull-Rom because its
/// first derivatives are exact instead of differenced, and over a bicubic spline because each cell
/// needs only its four corners (no global solve).
///
/// \par Measured
/// (g++ -O2, urdf/scanhead.urdf with the default OpticsConfig, n = 65, h = 0.175 m, 257 × 257
/// probes; error = \f$|h(q_{table}(x)) - x|\f$; test_correction_table.cpp asserts these):
/// \code
///   nominal            bilinear max 4.192 µm, RMS 1.797 µm;  bicubic max 0.0462 nm, RMS 0.0196 nm
///   optTable2DefectSet bilinear max 4.191 µm, RMS 1.796 µm;  bicubic max 0.0462 nm, RMS 0.0196 nm
/// \endcode
/// (worst points in the corner cells). Halving Δ divides the errors by 3.95 (bilinear,
/// \f$O(\Delta^2)\f$) and 16.7 (bicubic, \f$O(\Delta^4)\f$): 33 nodes give 16.5 µm / 0.77 nm,
/// 129 nodes 1.05 µm / 2.9 pm. Points more than 1 nm (kEdgeTolerance_m, rounding of computed edge
/// points) outside \f$[-h, h]^2\f$ throw NumericalError naming the point.
/// Build 65 × 65: ~2.5 ms. joints() along a raster path: bilinear ≈ 6 ns, bicubic ≈ 14 ns per call.
class CorrectionTable
{
public:
  /// \brief Solves the inverse model (Newton, OpticalModel::inverse) at every node.
  /// \param[in] nodes          n >= 2 per axis
  /// \param[in] half_width_m   h > 0: the table covers [−h, h]² [m]
  /// \throws ConfigError on bad n or h; NumericalError naming a node the optics cannot reach
  static CorrectionTable build(const OpticalModel& optics, int nodes, double half_width_m);

  /// \brief Reads a table file.
  ///
  /// \details File format (text, one record per line, '#' lines after the first are comments,
  /// blank lines ignored, fields separated by spaces or tabs):
  /// \code
  /// # scanhead correction table v1
  /// nodes 65
  /// half_width_m 0.17499999999999999
  /// columns i j q_x_rad q_y_rad dq_x_dx dq_y_dx dq_x_dy dq_y_dy d2q_x_dxdy d2q_y_dxdy
  /// 0 0 -0.11615888703535479 -0.12280797428169331 0.64017145388742425 ...  (n² node lines: j outer, i inner)
  /// \endcode
  /// The first line is the version. The keys nodes (integer, 2..2049), half_width_m (> 0, [m])
  /// and columns (exactly the list above) must all come before the first node line. Node lines
  /// give the indices i j (checked: row-major order) and the eight numbers: joint angles [rad],
  /// first derivatives [rad/m] and cross derivatives [rad/m²] of q_x and q_y, all written with 17
  /// significant digits (fullPrecisionText) so that a loaded table interpolates bit-identically.
  /// \throws InputError naming the file, the line and what is wrong
  static CorrectionTable load(const std::string& path);

  /// \brief The table file format of load() from text (\p source names it in errors; the fuzz target).
  static CorrectionTable parse(const std::string& text, const std::string& source);

  /// \brief Writes the table file (format on load()) atomically (temporary file + rename).
  /// \throws InputError
  void save(const std::string& path) const;

  /// \brief Interpolated joint angles at \p spot_m [rad].
  /// \throws NumericalError if the point lies outside [−h, h]² (names the point)
  Eigen::Vector2d joints(const Eigen::Vector2d& spot_m, TableInterpolation interpolation) const;

  /// \brief Bicubic joint angles (bit-identical to joints(spot_m, Bicubic)) and the bilinear
  /// interpolation of the nodes' exact \f$\partial q/\partial x\f$ (= J⁻¹ there): a Newton
  /// start and step matrix for the exact inverse (the NC's IGT).
  /// \return false, leaving the outputs untouched, if the point lies outside [−h, h]² (no throw)
  bool jointsAndInverseJacobian(const Eigen::Vector2d& spot_m, Eigen::Vector2d& q, Eigen::Matrix2d& dq_dx) const;

  /// \brief jointsAndInverseJacobian() of \p n points at once, structure of arrays; bit-identical
  /// to it point by point (one routine computes both).
  /// \param[in] x, y        the points [m]
  /// \param[out] q_x, q_y   bicubic joint angles [rad]; 0 where the point lies outside [−h, h]²
  /// \param[out] m00, m01, m10, m11  ∂q/∂x, row-major (m01 = ∂q_x/∂y) [rad/m]; 0 outside
  /// \param[out] ok         1 inside, 0 outside (no throw)
  void predictBlock(std::size_t n, const double* x, const double* y, double* q_x, double* q_y, double* m00, double* m01,
                    double* m10, double* m11, unsigned char* ok) const;

  int nodes() const { return nodes_; }
  double halfWidth() const { return half_width_m_; }

private:
  /// One node: angles and their derivatives w.r.t. the spot (one 64-byte cache line).
  struct Node
  {
    double q[2] = {0.0, 0.0};     ///< (q_x, q_y) [rad]
    double q_x[2] = {0.0, 0.0};   ///< ∂q/∂x [rad/m] (exact: first column of J⁻¹)
    double q_y[2] = {0.0, 0.0};   ///< ∂q/∂y [rad/m] (exact: second column of J⁻¹)
    double q_xy[2] = {0.0, 0.0};  ///< ∂²q/∂x∂y [rad/m²] (differenced over the grid)
  };

  struct Cell;  ///< a point's cell and its interpolation (correction_table.cpp)

  /// Sets n, h, the spacing and n² zero nodes.
  void setShape(int nodes, double half_width_m);
  /// The reader of load() and parse(): \p bytes is the size of the whole text (bounds the node count).
  static CorrectionTable read(std::istream& in, std::uint64_t bytes, const std::string& path);
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
  double max_error_m = 0.0;  ///< max |h(q_table(x)) − x| over the probes [m], h the direct model
  double rms_error_m = 0.0;  ///< RMS of the same [m]
  Eigen::Vector2d worst_point_m = Eigen::Vector2d::Zero();  ///< where the max is [m]
  int probes_per_axis = 0;                                  ///< probes x_k = −h + k·2h/(p−1) in each axis
};

/// \brief Error of \p table with \p interpolation: each probe x goes through the table, then the
/// direct model: e = |h(q_table(x)) − x| at the plane. \param probes_per_axis p >= 2
TableErrorReport measureTableError(const CorrectionTable& table, TableInterpolation interpolation,
                                   const OpticalModel& optics, int probes_per_axis);
}  // namespace scanhead
