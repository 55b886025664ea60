/// \file layer_window.cpp
/// \brief The moving window's fields: placement and re-centring, faces, sampling.
#include "scanhead/thermal/layer_window.hpp"

#include <algorithm>
#include <cmath>

namespace scanhead
{
void LayerWindow::allocate(int n_cells, double cell_side_m, const CellMaterials& cell_materials)
{
  n = n_cells;
  cell_m = cell_side_m;
  materials = cell_materials;
  const std::size_t cells = static_cast<std::size_t>(n) * n;
  t.assign(cells, 0.0);
  inv_kappa.assign(cells, 0.0);
  lambda.assign(cells, 0.0);
  fx.assign(cells, 0.0);
  fy.assign(cells, 0.0);
  solid.assign(cells, 0);
  src.assign(cells, 0.0);
  scratch.assign(cells, 0.0);
  reset();
}

void LayerWindow::reset()
{
  std::fill(t.begin(), t.end(), 0.0);
  std::fill(src.begin(), src.end(), 0.0);
  std::fill(solid.begin(), solid.end(), 0);
  std::fill(inv_kappa.begin(), inv_kappa.end(), 1.0 / materials.kappa_powder);
  std::fill(lambda.begin(), lambda.end(), materials.lambda_powder);
  std::fill(fx.begin(), fx.end(), materials.lambda_powder);
  std::fill(fy.begin(), fy.end(), materials.lambda_powder);
  placed = false;
  oi = oj = 0;
  box = CellBox();
}

void LayerWindow::place(const Eigen::Vector2d& centre, const MeltedRecord& record, double& left_window_j)
{
  const double kappa_s = materials.kappa_solid, kappa_p = materials.kappa_powder;
  const std::int64_t new_oi = static_cast<std::int64_t>(std::floor(centre.x() / cell_m)) - n / 2;
  const std::int64_t new_oj = static_cast<std::int64_t>(std::floor(centre.y() / cell_m)) - n / 2;
  if (placed && new_oi == oi && new_oj == oj)
    return;
  if (placed && !box.empty())
  {
    // Move the hot box (T = 0 elsewhere); what falls off carries its energy away.
    const std::int64_t di = new_oi - oi, dj = new_oj - oj;
    std::vector<double>& tmp = scratch;
    CellBox nb;
    nb.i0 = static_cast<int>(std::max<std::int64_t>(0, box.i0 - di));
    nb.i1 = static_cast<int>(std::min<std::int64_t>(n - 1, box.i1 - di));
    nb.j0 = static_cast<int>(std::max<std::int64_t>(0, box.j0 - dj));
    nb.j1 = static_cast<int>(std::min<std::int64_t>(n - 1, box.j1 - dj));
    if (nb.empty())
      nb = CellBox();
    for (int j = nb.j0; j <= nb.j1; ++j)
      std::fill(tmp.begin() + static_cast<std::size_t>(j) * n + nb.i0,
                tmp.begin() + static_cast<std::size_t>(j) * n + nb.i1 + 1, 0.0);
    for (int j = box.j0; j <= box.j1; ++j)
    {
      for (int i = box.i0; i <= box.i1; ++i)
      {
        const std::size_t k = static_cast<std::size_t>(j) * n + i;
        const double tk = t[k];
        if (tk == 0.0)
          continue;
        t[k] = 0.0;
        const std::int64_t ni = i - di, nj = j - dj;
        if (ni < 0 || nj < 0 || ni >= n || nj >= n)
          left_window_j += (solid[k] ? kappa_s : kappa_p) * tk * materials.h_area;
        else
          tmp[static_cast<std::size_t>(nj) * n + static_cast<std::size_t>(ni)] = tk;
      }
    }
    for (int j = nb.j0; j <= nb.j1; ++j)
    {
      for (int i = nb.i0; i <= nb.i1; ++i)
      {
        const std::size_t k = static_cast<std::size_t>(j) * n + i;
        t[k] = tmp[k];
      }
    }
    box = nb;  // empty when nothing is left
  }
  else
  {
    box = CellBox();
  }
  oi = new_oi;
  oj = new_oj;
  placed = true;
  // States from the global record (it holds every cell that ever switched).
  for (int j = 0; j < n; ++j)
  {
    const std::int64_t gj = oj + j;
    for (int i = 0; i < n;)
    {
      const std::int64_t gi = oi + i;
      const std::int64_t ti = MeltedRecord::tileOf(gi);
      const int run = static_cast<int>(std::min<std::int64_t>(n - i, 64 * (ti + 1) - gi));
      record.readRun(gi, gj, run, &solid[static_cast<std::size_t>(j) * n + i]);
      i += run;
    }
  }
  for (std::size_t k = 0; k < solid.size(); ++k)
  {
    inv_kappa[k] = 1.0 / (solid[k] ? kappa_s : kappa_p);
    lambda[k] = solid[k] ? materials.lambda_solid : materials.lambda_powder;
  }
  for (int j = 0; j < n; ++j)
  {
    for (int i = 0; i < n; ++i)
    {
      const std::size_t k = static_cast<std::size_t>(j) * n + i;
      if (i + 1 < n)
        fx[k] = materials.face(lambda[k], lambda[k + 1]);
      if (j + 1 < n)
        fy[k] = materials.face(lambda[k], lambda[k + n]);
    }
  }
}

void LayerWindow::updateFaces(int i, int j)
{
  const std::size_t k = static_cast<std::size_t>(j) * n + i;
  if (i + 1 < n)
    fx[k] = materials.face(lambda[k], lambda[k + 1]);
  if (i > 0)
    fx[k - 1] = materials.face(lambda[k - 1], lambda[k]);
  if (j + 1 < n)
    fy[k] = materials.face(lambda[k], lambda[k + n]);
  if (j > 0)
    fy[k - n] = materials.face(lambda[k - n], lambda[k]);
}

double LayerWindow::sampleLocal(double u, double v) const
{
  double x = u - 0.5, y = v - 0.5;
  x = std::min(std::max(x, 0.0), static_cast<double>(n - 1));
  y = std::min(std::max(y, 0.0), static_cast<double>(n - 1));
  int i = static_cast<int>(x), j = static_cast<int>(y);
  if (i > n - 2)
    i = n - 2;
  if (j > n - 2)
    j = n - 2;
  const double wx = x - i, wy = y - j;
  const double* r0 = &t[static_cast<std::size_t>(j) * n + i];
  const double* r1 = r0 + n;
  return (1.0 - wy) * ((1.0 - wx) * r0[0] + wx * r0[1]) + wy * ((1.0 - wx) * r1[0] + wx * r1[1]);
}

double LayerWindow::riseAt(const Eigen::Vector2d& p) const
{
  if (!placed || !p.allFinite())
    return 0.0;
  const double u = p.x() / cell_m - static_cast<double>(oi), v = p.y() / cell_m - static_cast<double>(oj);
  if (u < 0.0 || v < 0.0 || u > n || v > n)
    return 0.0;
  return sampleLocal(u, v);
}

double LayerWindow::storedEnergy() const
{
  double stored = 0.0;
  if (!box.empty())
  {
    for (int j = box.j0; j <= box.j1; ++j)
    {
      const std::size_t row = static_cast<std::size_t>(j) * n;
      for (int i = box.i0; i <= box.i1; ++i)
        stored += (solid[row + i] ? materials.kappa_solid : materials.kappa_powder) * t[row + i];
    }
  }
  return stored * materials.h_area;
}

ThermalWindow LayerWindow::snapshot() const
{
  ThermalWindow w;
  w.cell_m = cell_m;
  w.origin_i = oi;
  w.origin_j = oj;
  w.width = w.height = n;
  w.rise_k = t;
  w.solid = solid;
  return w;
}
}  // namespace scanhead
