/// \file lod_solver.cpp
/// \brief LOD backward Euler sweeps with Thomas solves.
#include "scanhead/thermal/lod_solver.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>

namespace scanhead
{
LossHalfStep lossHalfStep(double dt_s, double loss_w_m3k, const CellMaterials& materials)
{
  const double kappa_s = materials.kappa_solid, kappa_p = materials.kappa_powder;
  LossHalfStep f;
  f.decay_solid = std::exp(-0.5 * dt_s * loss_w_m3k / kappa_s);
  f.decay_powder = std::exp(-0.5 * dt_s * loss_w_m3k / kappa_p);
  f.lost_solid = -std::expm1(-0.5 * dt_s * loss_w_m3k / kappa_s) * kappa_s * materials.h_area;
  f.lost_powder = -std::expm1(-0.5 * dt_s * loss_w_m3k / kappa_p) * kappa_p * materials.h_area;
  return f;
}

void lodSweepX(LayerWindow& window, const CellBox& b, bool first, double dt_s, const LossHalfStep& loss, double& lost_j)
{
  const int n = window.n;
  const double r0 = dt_s / (window.cell_m * window.cell_m);
  const double sk = 1.0 / window.materials.h_area;
  const double fs = loss.decay_solid, fp = loss.decay_powder;
  const double ls = loss.lost_solid, lp = loss.lost_powder;
  double* const t = window.t.data();
  double* const cp = window.scratch.data();
  const double* const fx = window.fx.data();
  const double* const inv_kappa = window.inv_kappa.data();
  const double* const src = window.src.data();
  const std::uint8_t* const solid = window.solid.data();
  constexpr int kRows = 8;  // rows eliminated together: independent chains overlap in the pipeline
  double lost = 0.0;
  for (int jb = b.j0; jb <= b.j1; jb += kRows)
  {
    const int nr = std::min(kRows, b.j1 - jb + 1);
    double prev_c[kRows] = {}, prev_d[kRows] = {};
    for (int i = b.i0; i <= b.i1; ++i)
    {
      const bool has_w = i > b.i0, has_e = i < b.i1;
      for (int r = 0; r < nr; ++r)
      {
        const std::size_t k = static_cast<std::size_t>(jb + r) * n + i;
        const double west = has_w ? fx[k - 1] : 0.0;
        const double east = has_e ? fx[k] : 0.0;
        const double ik = inv_kappa[k];
        const double rr = r0 * ik;
        const double a = -rr * west, c = -rr * east;
        const double diag = 1.0 + rr * (west + east);
        double rhs = t[k];
        if (first)
        {
          const bool sol = solid[k] != 0;
          lost += (sol ? ls : lp) * rhs;
          rhs = rhs * (sol ? fs : fp) + src[k] * ik * sk;
        }
        const double m = 1.0 / (diag - a * prev_c[r]);
        prev_c[r] = c * m;
        prev_d[r] = (rhs - a * prev_d[r]) * m;
        cp[k] = prev_c[r];
        t[k] = prev_d[r];
      }
    }
    double x[kRows];
    for (int r = 0; r < nr; ++r)
      x[r] = t[static_cast<std::size_t>(jb + r) * n + b.i1];
    for (int i = b.i1 - 1; i >= b.i0; --i)
    {
      for (int r = 0; r < nr; ++r)
      {
        const std::size_t k = static_cast<std::size_t>(jb + r) * n + i;
        x[r] = t[k] - cp[k] * x[r];
        t[k] = x[r];
      }
    }
  }
  lost_j += lost;
}

void lodSweepY(LayerWindow& window, const CellBox& b, bool first, double dt_s, const LossHalfStep& loss, double& lost_j)
{
  const int n = window.n;
  const double r0 = dt_s / (window.cell_m * window.cell_m);
  const double sk = 1.0 / window.materials.h_area;
  const double fs = loss.decay_solid, fp = loss.decay_powder;
  const double ls = loss.lost_solid, lp = loss.lost_powder;
  const int i0 = b.i0, i1 = b.i1;
  double lost = 0.0;
  for (int j = b.j0; j <= b.j1; ++j)
  {
    const std::size_t row = static_cast<std::size_t>(j) * n;
    double* t = &window.t[row];
    double* cp = &window.scratch[row];
    const double* ik = &window.inv_kappa[row];
    const double* s = &window.src[row];
    const std::uint8_t* sol = &window.solid[row];
    const double* fn = &window.fy[row];
    const bool has_s = j > b.j0, has_n = j < b.j1;
    const double* fsouth = has_s ? &window.fy[row - n] : nullptr;
    const double* tp = has_s ? &window.t[row - n] : nullptr;
    const double* cpp = has_s ? &window.scratch[row - n] : nullptr;
    for (int i = i0; i <= i1; ++i)
    {
      const double south = has_s ? fsouth[i] : 0.0;
      const double north = has_n ? fn[i] : 0.0;
      const double r = r0 * ik[i];
      const double a = -r * south, c = -r * north;
      const double diag = 1.0 + r * (south + north);
      double rhs = t[i];
      if (first)
      {
        lost += (sol[i] ? ls : lp) * rhs;
        rhs = rhs * (sol[i] ? fs : fp) + s[i] * ik[i] * sk;
      }
      const double m = has_s ? 1.0 / (diag - a * cpp[i]) : 1.0 / diag;
      cp[i] = c * m;
      t[i] = has_s ? (rhs - a * tp[i]) * m : rhs * m;
    }
  }
  for (int j = b.j1 - 1; j >= b.j0; --j)
  {
    const std::size_t row = static_cast<std::size_t>(j) * n;
    double* t = &window.t[row];
    const double* cp = &window.scratch[row];
    const double* tn = &window.t[row + n];
    for (int i = i0; i <= i1; ++i)
      t[i] -= cp[i] * tn[i];
  }
  lost_j += lost;
}
}  // namespace scanhead
