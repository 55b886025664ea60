/// \file lod_solver.hpp
/// \brief One time step of the diffusion of PATH eq. 5 on the LayerWindow: locally one-dimensional
/// (LOD) backward Euler, one tridiagonal (Thomas) solve per row, then per column, with the loss term
/// split exactly around it (Strang).
#pragma once

#include "scanhead/thermal/layer_window.hpp"

namespace scanhead
{
/// \brief The exact half-step loss of one step of length dt, per cell state:
/// \f[ f = \exp\!\left(-\tfrac{1}{2}\,dt\,\frac{\lambda_s/\delta^2}{\kappa}\right),\qquad
///     \text{lost} = (1 - f)\,\kappa\,h\,\text{cell}^2 \f]
/// (T ← f·T removes lost·T joules from a cell).
struct LossHalfStep
{
  double decay_solid = 1.0, decay_powder = 1.0;  ///< f of a melted / powder cell
  double lost_solid = 0.0, lost_powder = 0.0;    ///< (1 − f)·κ·h·cell² [J/K]
};

/// \brief LossHalfStep for a step of \p dt_s [s] with loss coefficient \p loss_w_m3k = λ_s/δ²
/// [W/(m³·K)] (ThermalConfig::lossCoefficient()).
LossHalfStep lossHalfStep(double dt_s, double loss_w_m3k, const CellMaterials& materials);

/// \brief Backward Euler on the x part of the diffusion over box \p b, each row a Thomas solve:
/// \f[ \left(1 + r_i (W + E)\right) T'_i - r_i W\,T'_{i-1} - r_i E\,T'_{i+1} = T_i,\qquad
///     r_i = \frac{dt}{\kappa_i\,\text{cell}^2} \f]
/// W, E the face conductivities (0 at the box edge: adiabatic). With \p first, the right-hand side
/// is first f·T (half the loss, booked into \p lost_j) plus the step's source
/// E_src,i/(κ_i h cell²) (window.src). Each tridiagonal matrix is an M-matrix: unconditionally
/// stable, T ≥ 0 for any dt / cell². 8 rows are eliminated together (independent recurrences
/// overlap in the pipeline; the arithmetic of each row is that of a plain Thomas solve).
/// \param[in,out] window its t is replaced by T'; scratch holds the eliminated coefficients
/// \param[in,out] lost_j incremented by the energy of the half loss when \p first [J]
/// \pre \p b non-empty and inside the window
void lodSweepX(LayerWindow& window, const CellBox& b, bool first, double dt_s, const LossHalfStep& loss,
               double& lost_j);

/// \brief The same along y (columns; faces fy), all columns of the box eliminated row by row.
/// \pre \p b non-empty and inside the window
void lodSweepY(LayerWindow& window, const CellBox& b, bool first, double dt_s, const LossHalfStep& loss,
               double& lost_j);
}  // namespace scanhead
