/// \file gauss_legendre.hpp
/// \brief Gauss–Legendre rules on [0, 1] (private to src/energy): the quadrature of the stroke deposit's erf bracket.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>

namespace scanhead::energy_detail
{
/// \brief The n-point Gauss–Legendre rule on [0, 1]: ∫₀¹ f ≈ Σ weight[i]·f(node[i]), exact for polynomials of degree
/// ≤ 2n − 1 (Abramowitz & Stegun 25.4.29–30).
struct GaussLegendreRule
{
  static constexpr int kMaxNodes = 16;
  int n = 0;
  std::array<double, kMaxNodes> node{}, weight{};
};

/// \brief The rule of \p n points, 1 ≤ n ≤ kMaxNodes: the roots of P_n by Newton's method from Tricomi's estimate
/// cos(π(i + 3/4)/(n + 1/2)) and w = 2/((1 − x²)P_n'(x)²) (the recipe of Press et al., Numerical Recipes §4.6,
/// "gauleg"), mapped from [−1, 1] to [0, 1]. Accurate to ~1e-15; computed once per n (thread-safe statics).
inline const GaussLegendreRule& gaussLegendreRule(int n)
{
  static const std::array<GaussLegendreRule, GaussLegendreRule::kMaxNodes + 1> rules = [] {
    std::array<GaussLegendreRule, GaussLegendreRule::kMaxNodes + 1> all{};
    for (int m = 1; m <= GaussLegendreRule::kMaxNodes; ++m)
    {
      GaussLegendreRule& rule = all[m];
      rule.n = m;
      for (int i = 0; i < m; ++i)
      {
        double x = std::cos(M_PI * (i + 0.75) / (m + 0.5));
        double derivative = 1.0;
        for (int iteration = 0; iteration < 100; ++iteration)
        {
          // P_m(x) by the three-term recurrence, and P_m'(x) = m(x P_m − P_{m−1})/(x² − 1).
          double p0 = 1.0, p1 = 0.0;
          for (int k = 1; k <= m; ++k)
          {
            const double p2 = p1;
            p1 = p0;
            p0 = ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p2) / k;
          }
          derivative = m * (x * p0 - p1) / (x * x - 1.0);
          const double step = p0 / derivative;
          x -= step;
          if (std::abs(step) < 1e-15)
            break;
        }
        // Root i counts down from +1: node m−1−i on [0, 1] counts up.
        rule.node[m - 1 - i] = 0.5 * (1.0 + x);
        rule.weight[m - 1 - i] = 1.0 / ((1.0 - x * x) * derivative * derivative);  // ½ · 2/((1 − x²)P')
      }
    }
    return all;
  }();
  return rules[n];
}

/// \brief Nodes of the rule for a stroke's bracket erf(u) − erf(u − √A) = (2/√π)√A∫₀¹ e^{−(u − √Aτ)²}dτ
/// (segment_integral.hpp), √A ≤ 6: n = max(4, ⌈2√A + 2⌉) ≤ 14. The integrand is a Gaussian of width ~1/√A in τ; the
/// worst error over u (against erf in double, for √A from 0.05 to 6) is 9.5e-7 at √A = 1 with 4 nodes and ≤ 7.4e-7
/// above, of a bracket whose peak is up to 2: no more than the lane erf's 4e-6 (test_stroke_deposit.cpp).
inline int bracketRuleNodes(double sqrt_a)
{
  return std::clamp(static_cast<int>(std::ceil(2.0 * sqrt_a + 2.0)), 4, 14);
}
}  // namespace scanhead::energy_detail
