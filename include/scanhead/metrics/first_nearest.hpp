/// \file first_nearest.hpp
/// \brief The nearest of a window of actual samples to a commanded point (the same-instant contour error's search,
/// LayerQuality: ~41 samples for each of a layer's 30 M commands).
#pragma once

#include <cstddef>

namespace scanhead
{
/// \brief Offset of the first smallest of (x_i − cx)² + (y_i − cy)², i < n, and that value in \p best_d2 (the loop
/// `if (d2 < best) best = d2, at = i` from best = +inf, at = 0: NaN never wins, ties keep the first; n = 0 gives 0 and
/// +inf). Two passes: the smallest value in four lanes (a minimum carries no offsets along, so the lanes stay in
/// registers: ~4× faster than eight lanes carrying offsets, 38 vs 144 ns on 41 samples on the development VM), then the
/// first offset whose value equals it (the same expression, so the same bits; half the window on average).
std::size_t firstNearest(const double* x, const double* y, std::size_t n, double cx, double cy, double& best_d2);
}  // namespace scanhead
