/// \file box_filter.cpp
/// \brief Taps of the exact-duration box filter (SPEC §2.3).
#include "scanhead/common/box_filter.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "scanhead/common/errors.hpp"

namespace scanhead
{
namespace
{
/// y[i] = Σ_j w[j]·(h[i + j] − h[i + taps − 1]) for i < count, each sum added in the order
/// j = 0, 1, … as average() adds it; j is the outer loop so the samples vectorise. AVX2 clone:
/// the same operations (no FMA), so the same bits.
__attribute__((target_clones("avx2", "default"))) void tapSums(const double* __restrict h, const double* __restrict w,
                                                               std::size_t taps, std::size_t count,
                                                               double* __restrict y)
{
  const double* latest = h + (taps - 1);
  for (std::size_t i = 0; i < count; ++i)
  {
    y[i] = 0.0;
  }
  for (std::size_t j = 0; j < taps; ++j)
  {
    const double wj = w[j];
    const double* hj = h + j;
    for (std::size_t i = 0; i < count; ++i)
    {
      y[i] += wj * (hj[i] - latest[i]);
    }
  }
}

/// d[i] = (h[i + m + 1] − ((1 − f)·h[i + 1] + f·h[i])) / T for i < count: derivative() of each
/// sample of the block (x_n − x(t_n − T))/T with the same operations (h[i + m + 1] = x_n,
/// h[i + 1] = x_{n−m}, h[i] = x_{n−m−1}); AVX2 clone without FMA, so the same bits.
__attribute__((target_clones("avx2", "default"))) void delayDifferences(const double* __restrict h, std::size_t m,
                                                                        double f, double scale_s, std::size_t count,
                                                                        double* __restrict d)
{
  const double g = 1.0 - f;
  for (std::size_t i = 0; i < count; ++i)
  {
    d[i] = (h[i + m + 1] - (g * h[i + 1] + f * h[i])) / scale_s;
  }
}
}  // namespace

template <int N>
void BoxFilter<N>::pushBlock(const Vector* x, std::size_t count, Vector* average, Vector* derivative,
                             int average_channels)
{
  // h[k] = x_{n0 − history + k}: the history (sampleAgo(history − 1 − k) before the block), then x.
  const std::size_t history = taps_ - 1;
  block_history_.resize(history + count);
  block_sums_.resize(count);
  for (int c = 0; c < N; ++c)
  {
    for (std::size_t k = 0; k < history; ++k)
    {
      block_history_[k] = sampleAgo(history - 1 - k)[c];
    }
    for (std::size_t i = 0; i < count; ++i)
    {
      block_history_[history + i] = x[i][c];
    }
    if (c < average_channels)
    {
      tapSums(block_history_.data(), weights_.data(), taps_, count, block_sums_.data());
      for (std::size_t i = 0; i < count; ++i)
      {
        average[i][c] = block_history_[history + i] + block_sums_[i];
      }
    }
    if (derivative != nullptr)
    {
      // derivative(), sample by sample of the block: the backward difference if T = 0
      if (identity_)
      {
        for (std::size_t i = 0; i < count; ++i)
        {
          derivative[i][c] = (block_history_[history + i] - block_history_[history + i - 1]) / period_s_;
        }
      }
      else
      {
        // history = m + 1, so h[i + m + 1] is sample i of the block
        delayDifferences(block_history_.data(), whole_, frac_, duration_s_, count, block_sums_.data());
        for (std::size_t i = 0; i < count; ++i)
        {
          derivative[i][c] = block_sums_[i];
        }
      }
    }
  }
  // The ring keeps the last taps samples: pushing only those leaves the same window (every read
  // is relative to head_).
  for (std::size_t i = count > taps_ ? count - taps_ : 0; i < count; ++i)
  {
    push(x[i]);
  }
}

template <int N>
BoxFilter<N>::BoxFilter()
  : BoxFilter(0.0, 1e-5)
{
}

template <int N>
BoxFilter<N>::BoxFilter(double duration_s, double period_s)
{
  if (!(std::isfinite(duration_s) && duration_s >= 0.0) || !(std::isfinite(period_s) && period_s > 0.0))
  {
    std::ostringstream msg;
    msg << "BoxFilter: duration must be >= 0 and period > 0 (got duration " << duration_s << " s, period " << period_s
        << " s)";
    throw ConfigError(msg.str());
  }
  period_s_ = period_s;
  double ratio = duration_s / period_s;  // T/Ts = m + f
  const double nearest = std::round(ratio);
  if (std::abs(ratio - nearest) <= 1e-9 * std::max(1.0, ratio))
  {
    ratio = nearest;  // 260e-6/1e-5 is 25.999999999999996 in double: it means 26 periods
  }
  whole_ = static_cast<std::size_t>(std::floor(ratio));
  frac_ = ratio - static_cast<double>(whole_);
  identity_ = (ratio == 0.0);
  duration_s_ = ratio * period_s;
  taps_ = whole_ + 2;

  // w[k] multiplies x_{n−k}: trapezoids over the m whole periods, exact partial trapezoid
  // over the fraction f (from x(t_n − T) = (1−f)·x_{n−m} + f·x_{n−m−1} to x_{n−m}).
  std::vector<double> w(taps_, 0.0);
  if (identity_)
  {
    w[0] = 1.0;
  }
  else
  {
    for (std::size_t k = 0; k < whole_; ++k)
    {
      w[k] += 0.5;
      w[k + 1] += 0.5;
    }
    w[whole_] += frac_ - 0.5 * frac_ * frac_;
    w[whole_ + 1] += 0.5 * frac_ * frac_;
    for (double& wk : w)
    {
      wk /= ratio;
    }
  }
  weights_.assign(taps_, 0.0);
  for (std::size_t j = 0; j < taps_; ++j)
  {
    weights_[j] = w[taps_ - 1 - j];
  }
  buffer_.resize(N, static_cast<Eigen::Index>(2 * taps_));
  reset(Vector::Zero());
}

template <int N>
void BoxFilter<N>::reset(const Vector& initial)
{
  for (Eigen::Index c = 0; c < buffer_.cols(); ++c)
  {
    buffer_.col(c) = initial;
  }
  head_ = 0;
}

template class BoxFilter<1>;
template class BoxFilter<2>;
template class BoxFilter<4>;
}  // namespace scanhead
