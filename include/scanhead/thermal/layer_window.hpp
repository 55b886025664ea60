/// \file layer_window.hpp
/// \brief The moving window of the thermal layer model: its cell fields (rise, κ, λ, face
/// conductivities, powder/solid state), its placement on the global grid and re-centring, and
/// bilinear sampling (PATH eq. 1 for the cell properties).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "scanhead/thermal/melted_record.hpp"
#include "scanhead/thermal/thermal_results.hpp"

namespace scanhead
{
/// \brief An inclusive box of window cells [i0, i1] × [j0, j1]; empty when i1 < i0 or j1 < j0.
struct CellBox
{
  int i0 = 0, i1 = -1, j0 = 0, j1 = -1;
  bool empty() const { return i1 < i0 || j1 < j0; }
};

/// \brief Material constants of the two cell states (PATH eq. 1; what "solid" means is
/// ThermalConfig::phase_switch's choice, made by the caller).
struct CellMaterials
{
  double kappa_solid = 0.0;    ///< κ = ρ c_p of a melted cell [J/(m³·K)]
  double kappa_powder = 0.0;   ///< of powder [J/(m³·K)]
  double lambda_solid = 0.0;   ///< λ of a melted cell [W/(m·K)]
  double lambda_powder = 0.0;  ///< of powder [W/(m·K)]
  double h_area = 0.0;         ///< layer thickness × cell² [m³]
  /// \brief Face conductivity from the two cells' λ (arithmetic or harmonic mean).
  double (*face)(double, double) = nullptr;
};

/// \brief The n × n window of cells (side cell_m) that follows the spot: fields row-major, row j = y.
///
/// Cell (i, j) of the window is global cell (oi + i, oj + j). Outside the active box the rise is
/// exactly 0. Cells entering the window on re-centring start at T = 0 and take their state from the
/// MeltedRecord (which holds every cell that ever switched); cells leaving carry their energy
/// h·κ·T·cell² away. The solver (lod_solver.hpp) and the layer model write the fields directly.
struct LayerWindow
{
  int n = 0;            ///< side [cells]
  double cell_m = 0.0;  ///< cell side [m]
  CellMaterials materials;
  std::vector<double> t;          ///< rise [K]
  std::vector<double> inv_kappa;  ///< 1/κ [m³·K/J]
  std::vector<double> lambda;     ///< cell conductivity [W/(m·K)]
  std::vector<double> fx, fy;  ///< face conductivities: fx between (i, j) and (i+1, j) at j·n + i, fy (i, j)–(i, j+1)
  std::vector<std::uint8_t> solid;
  std::vector<double> src;      ///< energy deposited this step [J]
  std::vector<double> scratch;  ///< Thomas coefficients / shift buffer
  bool placed = false;
  std::int64_t oi = 0, oj = 0;  ///< global index of window cell (0, 0)
  CellBox box;                  ///< active box (T = 0 outside)

  /// \brief Allocates the n × n fields (\p n_cells per side) and reset()s them.
  void allocate(int n_cells, double cell_side_m, const CellMaterials& cell_materials);
  /// \brief All powder at T = 0, not placed, empty active box.
  void reset();

  /// \brief Places the window's cell (n/2, n/2) on the cell holding \p centre (no-op if already
  /// there): the hot box moves with its cells, what falls off adds its energy to \p left_window_j;
  /// every cell's state is read back from \p record and the faces recomputed.
  void place(const Eigen::Vector2d& centre, const MeltedRecord& record, double& left_window_j);

  /// \brief Recomputes the four faces of cell (i, j) after its λ changed.
  void updateFaces(int i, int j);

  /// \brief Bilinear T at local cell coordinates (u, v), centres at k + 0.5, clamped to the
  /// outermost centres [K].
  double sampleLocal(double u, double v) const;

  /// \brief Bilinear T at \p p [m], 0 outside the window or before the first placement [K].
  double riseAt(const Eigen::Vector2d& p) const;

  /// \brief h·cell²·Σ κ·T over the active box [J].
  double storedEnergy() const;

  /// \brief The fields as a plain ThermalWindow.
  ThermalWindow snapshot() const;
};
}  // namespace scanhead
