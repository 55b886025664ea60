/// \file first_nearest.cpp
#include "scanhead/metrics/first_nearest.hpp"

#include <cmath>

namespace scanhead
{
namespace
{
/// Four doubles: one AVX2 register, two SSE2 ones (GCC lowers the vector type to what the clone's target has; every
/// lane does the same IEEE operations as the scalar expression, so every clone gives the same bits; the library is
/// built with -ffp-contract=off: no FMA).
typedef double Double4 __attribute__((vector_size(32)));
}  // namespace

__attribute__((target_clones("avx512f", "avx2", "default"))) std::size_t firstNearest(const double* x, const double* y,
                                                                                      std::size_t n, double cx,
                                                                                      double cy, double& best_d2)
{
  const Double4 vcx = {cx, cx, cx, cx}, vcy = {cy, cy, cy, cy};
  Double4 best = {INFINITY, INFINITY, INFINITY, INFINITY};
  std::size_t i = 0;
  for (; i + 4 <= n; i += 4)
  {
    Double4 vx, vy;
    __builtin_memcpy(&vx, x + i, sizeof vx);
    __builtin_memcpy(&vy, y + i, sizeof vy);
    const Double4 dx = vx - vcx, dy = vy - vcy;
    const Double4 d2 = dx * dx + dy * dy;
    best = d2 < best ? d2 : best;
  }
  double b = INFINITY;
  for (int lane = 0; lane < 4; ++lane)
    b = best[lane] < b ? best[lane] : b;
  for (; i < n; ++i)
  {
    const double dx = x[i] - cx, dy = y[i] - cy;
    const double d2 = dx * dx + dy * dy;
    b = d2 < b ? d2 : b;
  }
  best_d2 = b;
  if (!(b < INFINITY))
    return 0;  // no value below +inf (NaN or infinite distances): the loop's start
  for (i = 0; i < n; ++i)
  {
    const double dx = x[i] - cx, dy = y[i] - cy;
    if (dx * dx + dy * dy == b)
      return i;
  }
  return 0;  // not reached: b is one of the values
}
}  // namespace scanhead
