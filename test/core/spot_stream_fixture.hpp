/// \file spot_stream_fixture.hpp
/// \brief A spot stream built sample by sample and cut into chunks: what the energy-map and
/// thermal tests share.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <vector>

#include "scanhead/core/chunk.hpp"

namespace scanhead::test_support
{
constexpr double kStreamPeriod_s = 1e-5;  ///< NC period, 100 kHz

/// \brief Actual spot positions and laser powers, one per sample of kStreamPeriod_s.
struct SpotStream
{
  std::vector<Eigen::Vector2d> pos;
  std::vector<double> power;

  void add(const Eigen::Vector2d& p, double w)
  {
    pos.push_back(p);
    power.push_back(w);
  }
  /// \brief Straight line from \p a to \p b at speed v, power P (the last sample lands on b).
  void line(const Eigen::Vector2d& a, const Eigen::Vector2d& b, double v, double p)
  {
    const int n = std::max(1, static_cast<int>(std::round((b - a).norm() / (v * kStreamPeriod_s))));
    for (int k = 0; k <= n; ++k)
      add(a + (b - a) * (double(k) / n), p);
  }
  void dwell(const Eigen::Vector2d& a, int samples, double p)
  {
    for (int k = 0; k < samples; ++k)
      add(a, p);
  }
  double commandedEnergy() const  ///< Σ P·Ts [J]
  {
    double e = 0.0;
    for (double w : power)
      e += w * kStreamPeriod_s;
    return e;
  }
  /// \brief Samples [start, start + count) as a chunk (setpoint = actual).
  SpotChunk chunk(std::size_t start, std::size_t count) const
  {
    SpotChunk c;
    c.first_index = start;
    c.period_s = kStreamPeriod_s;
    for (std::size_t k = start; k < std::min(pos.size(), start + count); ++k)
    {
      SpotSample sample;
      sample.actual = pos[k];
      sample.setpoint = pos[k];
      sample.power_w = power[k];
      c.samples.push_back(sample);
    }
    return c;
  }
};
}  // namespace scanhead::test_support
