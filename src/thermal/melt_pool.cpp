/// \file melt_pool.cpp
/// \brief Melt-pool marching on the window and the steady statistics.
#include "scanhead/thermal/melt_pool.hpp"

#include <algorithm>
#include <cmath>

namespace scanhead
{
namespace
{
constexpr double kMarchStepCells = 1.0;      // melt-pool marching step [cells]
constexpr int kRefineHalvings = 3;           // then the bracket is halved 3 times (1/8 cell) and interpolated
constexpr double kWidthStationsCells = 1.0;  // spacing of the cross-track marches [cells]
}  // namespace

void measureMeltPool(const LayerWindow& window, int peak_i, int peak_j, const Eigen::Vector2d& dir, double melt_rise_k,
                     ThermalStep& step)
{
  const double melt_rise = melt_rise_k;
  const double u0 = peak_i + 0.5, v0 = peak_j + 0.5;
  const double lim_lo = 0.5, lim_hi = window.n - 0.5;
  bool edge = false;
  // Distance [cells] from (u, v) along (du, dv) to where T drops to melting.
  auto march = [&](double u, double v, double du, double dv) {
    double prev = window.sampleLocal(u, v);
    double s = 0.0;
    for (;;)
    {
      const double sn = s + kMarchStepCells;
      const double pu = u + sn * du, pv = v + sn * dv;
      if (pu < lim_lo || pv < lim_lo || pu > lim_hi || pv > lim_hi)
      {
        edge = true;
        return s;
      }
      double val = window.sampleLocal(pu, pv);
      if (val <= melt_rise)
      {
        // Bracket [s, sn]: halve it kRefineHalvings times, then interpolate linearly.
        double hi_s = sn;
        for (int k = 0; k < kRefineHalvings; ++k)
        {
          const double mid = 0.5 * (s + hi_s);
          const double vm = window.sampleLocal(u + mid * du, v + mid * dv);
          if (vm > melt_rise)
          {
            s = mid;
            prev = vm;
          }
          else
          {
            hi_s = mid;
            val = vm;
          }
        }
        return s + (hi_s - s) * (prev - melt_rise) / (prev - val);
      }
      prev = val;
      s = sn;
    }
  };
  const double du = dir.x(), dv = dir.y();
  const double front = march(u0, v0, du, dv);
  const double rear = march(u0, v0, -du, -dv);
  double width = 0.0;
  for (double s = -rear; s <= front; s += kWidthStationsCells)
  {
    const double pu = u0 + s * du, pv = v0 + s * dv;
    if (window.sampleLocal(pu, pv) <= melt_rise)
      continue;
    width = std::max(width, march(pu, pv, -dv, du) + march(pu, pv, dv, -du));
  }
  step.length_m = (front + rear) * window.cell_m;
  step.width_m = width * window.cell_m;
  step.pool_at_window_edge = edge;
}

void MeltPoolAccumulator::reset()
{
  stats_ = MeltPoolStats();
  sum_len_ = sum_len2_ = sum_wid_ = sum_wid2_ = sum_pk_ = sum_pk2_ = 0.0;
}

void MeltPoolAccumulator::add(const ThermalStep& step)
{
  MeltPoolStats& s = stats_;
  ++s.steps;
  if (step.laser_on)
    ++s.laser_on_steps;
  if (step.peak_k > melt_rise_k_)
    ++s.melting_steps;
  s.max_length_m = std::max(s.max_length_m, step.length_m);
  s.max_width_m = std::max(s.max_width_m, step.width_m);
  s.max_peak_k = std::max(s.max_peak_k, step.peak_k);
  if (!step.steady)
    return;
  ++s.steady_steps;
  sum_len_ += step.length_m;
  sum_len2_ += step.length_m * step.length_m;
  sum_wid_ += step.width_m;
  sum_wid2_ += step.width_m * step.width_m;
  sum_pk_ += step.peak_k;
  sum_pk2_ += step.peak_k * step.peak_k;
  const double n = static_cast<double>(s.steady_steps);
  auto spread = [n](double sum, double sum2) { return std::sqrt(std::max(0.0, sum2 / n - (sum / n) * (sum / n))); };
  s.steady_length_mean_m = sum_len_ / n;
  s.steady_width_mean_m = sum_wid_ / n;
  s.steady_peak_mean_k = sum_pk_ / n;
  s.steady_length_std_m = spread(sum_len_, sum_len2_);
  s.steady_width_std_m = spread(sum_wid_, sum_wid2_);
  s.steady_peak_std_k = spread(sum_pk_, sum_pk2_);
}
}  // namespace scanhead
