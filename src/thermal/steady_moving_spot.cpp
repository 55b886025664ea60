/// \file steady_moving_spot.cpp
/// \brief Steady moving-spot reference (constant solid properties): quadrature and root finding.
#include "scanhead/thermal/steady_moving_spot.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <vector>

namespace scanhead
{
namespace
{
double simpson(const std::function<double(double)>& f, double a, double b, double fa, double fm, double fb,
               double whole, double tol, int depth)
{
  const double m = 0.5 * (a + b);
  const double lm = 0.5 * (a + m), rm = 0.5 * (m + b);
  const double flm = f(lm), frm = f(rm);
  const double left = (m - a) / 6.0 * (fa + 4.0 * flm + fm);
  const double right = (b - m) / 6.0 * (fm + 4.0 * frm + fb);
  const double delta = left + right - whole;
  if (depth <= 0 || std::abs(delta) <= 15.0 * tol)
    return left + right + delta / 15.0;
  return simpson(f, a, m, fa, flm, fm, left, 0.5 * tol, depth - 1) +
         simpson(f, m, b, fm, frm, fb, right, 0.5 * tol, depth - 1);
}

double integrate(const std::function<double(double)>& f, double a, double b, double tol)
{
  const double fa = f(a), fb = f(b), fm = f(0.5 * (a + b));
  const double whole = (b - a) / 6.0 * (fa + 4.0 * fm + fb);
  return simpson(f, a, b, fa, fm, fb, whole, tol, 48);
}
}  // namespace

double steadyMovingSpotRise(const ThermalConfig& config, double power_w, double speed_m_s, double xi_m, double eta_m)
{
  const double kappa = config.kappaMelted();
  const double a = config.conductivityMelted() / kappa;
  const double tau = kappa / config.lossCoefficient();
  const double w = 0.5 * config.spot_diameter_m;
  const double s0 = 0.25 * w * w;
  const double pref = config.absorptivity * power_w / (config.layer_thickness_m * kappa);
  if (pref == 0.0)
    return 0.0;
  const double v = speed_m_s;
  auto f = [&](double t) {
    const double s2 = s0 + 2.0 * a * t;
    const double dx = xi_m + v * t;
    return std::exp(-t / tau - (dx * dx + eta_m * eta_m) / (2.0 * s2)) / (2.0 * M_PI * s2);
  };
  // Breakpoints: geometric from the spot's diffusion time, and around the passage time −ξ/v.
  std::vector<double> br{0.0};
  const double t_end = 60.0 * tau;
  for (double t = s0 / (2.0 * a) / 64.0; t < t_end; t *= 2.0)
    br.push_back(t);
  br.push_back(t_end);
  if (v > 0.0 && xi_m < 0.0)
  {
    const double tc = -xi_m / v;
    const double sig = std::sqrt(s0 + 2.0 * a * tc) / v;
    for (double k : {-6.0, -2.0, 0.0, 2.0, 6.0})
    {
      const double t = tc + k * sig;
      if (t > 0.0 && t < t_end)
        br.push_back(t);
    }
  }
  std::sort(br.begin(), br.end());
  const double tol = 1e-7 * config.meltRiseK() / pref / static_cast<double>(br.size());
  double sum = 0.0;
  for (std::size_t k = 0; k + 1 < br.size(); ++k)
  {
    if (br[k + 1] > br[k])
      sum += integrate(f, br[k], br[k + 1], tol);
  }
  return pref * sum;
}

SteadyMeltPool steadyMeltPool(const ThermalConfig& config, double power_w, double speed_m_s)
{
  SteadyMeltPool out;
  const double tm = config.meltRiseK();
  const double w = 0.5 * config.spot_diameter_m;
  auto axis = [&](double xi) { return steadyMovingSpotRise(config, power_w, speed_m_s, xi, 0.0); };
  // Peak on the axis: scan, then golden section.
  double best_xi = 0.0, best = -1.0;
  for (double xi = -8.0 * w; xi <= 2.0 * w; xi += w / 16.0)
  {
    const double t = axis(xi);
    if (t > best)
    {
      best = t;
      best_xi = xi;
    }
  }
  {
    const double g = 0.5 * (std::sqrt(5.0) - 1.0);
    double lo = best_xi - w / 16.0, hi = best_xi + w / 16.0;
    for (int it = 0; it < 40; ++it)
    {
      const double x1 = hi - g * (hi - lo), x2 = lo + g * (hi - lo);
      if (axis(x1) > axis(x2))
        hi = x2;
      else
        lo = x1;
    }
    best_xi = 0.5 * (lo + hi);
    best = axis(best_xi);
  }
  out.peak_k = best;
  out.peak_xi_m = best_xi;
  if (best <= tm)
    return out;
  // Crossing of tm along a ray from a point above it.
  auto cross = [&](const std::function<double(double)>& g) {
    double lo = 0.0, step = w;
    while (g(lo + step) > tm)
    {
      lo += step;
      step *= 2.0;
    }
    double hi = lo + step;
    while (hi - lo > 1e-9)
    {
      const double mid = 0.5 * (lo + hi);
      (g(mid) > tm ? lo : hi) = mid;
    }
    return 0.5 * (lo + hi);
  };
  out.front_m = best_xi + cross([&](double s) { return axis(best_xi + s); });
  out.rear_m = best_xi - cross([&](double s) { return axis(best_xi - s); });
  out.length_m = out.front_m - out.rear_m;
  auto half_width = [&](double xi) {
    if (axis(xi) <= tm)
      return 0.0;
    return cross([&](double eta) { return steadyMovingSpotRise(config, power_w, speed_m_s, xi, eta); });
  };
  const int n = 48;
  double best_w = 0.0, best_w_xi = best_xi;
  const double dxi = out.length_m / n;
  for (int k = 1; k < n; ++k)
  {
    const double xi = out.rear_m + k * dxi;
    const double hw = half_width(xi);
    if (hw > best_w)
    {
      best_w = hw;
      best_w_xi = xi;
    }
  }
  {
    const double g = 0.5 * (std::sqrt(5.0) - 1.0);
    double lo = best_w_xi - dxi, hi = best_w_xi + dxi;
    for (int it = 0; it < 30; ++it)
    {
      const double x1 = hi - g * (hi - lo), x2 = lo + g * (hi - lo);
      if (half_width(x1) > half_width(x2))
        hi = x2;
      else
        lo = x1;
    }
    best_w = std::max(best_w, half_width(0.5 * (lo + hi)));
  }
  out.width_m = 2.0 * best_w;
  return out;
}
}  // namespace scanhead
