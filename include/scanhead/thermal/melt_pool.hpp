/// \file melt_pool.hpp
/// \brief Melt-pool geometry of one thermal step (length along the scan direction, width across,
/// from the window's rise field) and the running statistics over the steps (MeltPoolStats).
#pragma once

#include <Eigen/Core>

#include "scanhead/thermal/layer_window.hpp"
#include "scanhead/thermal/thermal_results.hpp"

namespace scanhead
{
/// \brief Measures the melt pool around the hottest cell (\p peak_i, \p peak_j) of \p window into
/// step.length_m, step.width_m and step.pool_at_window_edge.
///
/// From the peak, along the scan direction \p dir (unit) and back, the bilinear T
/// (LayerWindow::sampleLocal) is sampled every cell until it drops to \p melt_rise_k or below; the
/// bracket is halved 3 times and the crossing interpolated linearly. The length is front + rear.
/// Across, the same from points every cell along that segment (those above melting), the widest
/// counting (width). Only the region connected to the peak along those lines counts. A march that
/// reaches the outermost cell centres stops there and sets pool_at_window_edge.
/// \pre the peak is above melting; \p dir is a unit vector
void measureMeltPool(const LayerWindow& window, int peak_i, int peak_j, const Eigen::Vector2d& dir, double melt_rise_k,
                     ThermalStep& step);

/// \brief Running MeltPoolStats: counts and maxima over all steps, mean and spread over the steady
/// ones (ThermalStep::steady), the spread from the running sums
/// \f[ \sigma = \sqrt{\max\!\left(0,\ \overline{x^2} - \bar{x}^2\right)} \f]
class MeltPoolAccumulator
{
public:
  /// \param[in] melt_rise_k a step whose peak is above it counts as melting [K]
  explicit MeltPoolAccumulator(double melt_rise_k = 0.0)
    : melt_rise_k_(melt_rise_k)
  {
  }

  /// \brief Forgets every step (melt_rise_k kept).
  void reset();
  /// \brief Counts one step.
  void add(const ThermalStep& step);
  const MeltPoolStats& stats() const { return stats_; }

private:
  double melt_rise_k_ = 0.0;
  MeltPoolStats stats_;
  double sum_len_ = 0.0, sum_len2_ = 0.0, sum_wid_ = 0.0, sum_wid2_ = 0.0, sum_pk_ = 0.0, sum_pk2_ = 0.0;
};
}  // namespace scanhead
