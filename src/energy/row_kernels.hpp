/// \file row_kernels.hpp
/// \brief Row kernels both deposit methods share (private to src/energy).
#pragma once

#include <cmath>

namespace scanhead::energy_detail
{
/// \brief The pixel centres o + (i + 0.5)p within [a, b] along one axis: i from firstCentre(a) to lastCentre(b).
inline double firstCentre(double a, double origin, double p)
{
  return std::ceil((a - origin) / p - 0.5);
}
inline double lastCentre(double b, double origin, double p)
{
  return std::floor((b - origin) / p - 0.5);
}

/// \brief 1-D Gaussian weights g[k] = exp(-a·d_k²), d_k = d_centre + (k − H)·p, k = 0..n−1 (n > H).
///
/// Recurrence from the centre outwards (3 exps instead of 2H+1): with r_k = exp(-a(2 d_k p + p²)),
/// g_{k+1} = g_k·r_k and r_{k+1} = r_k·q, q = exp(-2 a p²); mirrored to the left. Starting at the
/// centre pixel (|d| ≤ p/2, g ≈ 1 for the circular spot; a sheared row of an oblique spot starts
/// |shear·dy| ≤ sin²θ·R off its peak, still g ≥ 0.3 at 17° of incidence) keeps the relative error
/// ~H·1e-16 and lets far weights underflow to 0 harmlessly.
inline void gaussianWeights(double d_centre, double a, double p, double q, int half, int n, double* g)
{
  g[half] = std::exp(-a * d_centre * d_centre);
  double r = std::exp(-a * (2.0 * d_centre * p + p * p));
  for (int k = half; k + 1 < n; ++k)
  {
    g[k + 1] = g[k] * r;
    r *= q;
  }
  double l = std::exp(-a * (-2.0 * d_centre * p + p * p));
  for (int k = half; k > 0; --k)
  {
    g[k - 1] = g[k] * l;
    l *= q;
  }
}

/// \brief Σ x[k], k < n (any n), in 8 float lanes combined in double: a fixed order
/// (deterministic), short add chains; relative error ~1e-7 on a row of ≤ 1e4 weights in [0, 1e3],
/// and the stencil is normalised by these very sums, so the deposit conserves the energy anyway.
inline double sumRow(const float* x, int n)
{
  float lanes[8] = {};
  int k = 0;
  for (; k + 8 <= n; k += 8)
    for (int l = 0; l < 8; ++l)
      lanes[l] += x[k + l];
  for (; k < n; ++k)
    lanes[k % 8] += x[k];
  double sum = 0.0;
  for (const float lane : lanes)
    sum += lane;
  return sum;
}

}  // namespace scanhead::energy_detail
