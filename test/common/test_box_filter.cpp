/// \file test_box_filter.cpp
/// \brief The exact-duration box filter (SPEC §2.3) and the velocity saturation (SPEC §2.4).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "scanhead/common/box_filter.hpp"
#include "scanhead/common/errors.hpp"
#include "scanhead/nc/rate_limiter.hpp"

using scanhead::BoxFilter;

namespace
{
constexpr double kTs = 1e-5;

/// Exact (1/T)∫_{a}^{b} of the piecewise-linear signal through samples x (x[k] at k·Ts, held at
/// x[0] before 0), computed piece by piece with the trapezoid of the clipped interval: an
/// independent implementation of the filter's definition.
double exactMean(const std::vector<double>& x, double a, double b)
{
  auto value = [&x](double t) {
    if (t <= 0.0)
    {
      return x[0];
    }
    const double u = t / kTs;
    const std::size_t k = static_cast<std::size_t>(std::floor(u));
    if (k + 1 >= x.size())
    {
      return x.back();
    }
    const double f = u - static_cast<double>(k);
    return x[k] + f * (x[k + 1] - x[k]);
  };
  double integral = 0.0;
  double t = a;
  while (t < b)
  {
    // next breakpoint: a sample time strictly after t (or b)
    double next = (std::floor(t / kTs + 1e-12) + 1.0) * kTs;
    if (t < 0.0)
    {
      next = std::min(0.0, b);
    }
    next = std::min(next, b);
    integral += 0.5 * (value(t) + value(next)) * (next - t);
    t = next;
  }
  return integral / (b - a);
}
}  // namespace

// A ramp through a box of duration T comes out as the ramp delayed by exactly T/2, for T not a
// multiple of Ts. Tolerance 1e-12 relative: the output is a 30-tap weighted sum, rounding
// ~30·1e-16 relative; any error in the fractional weights would show at ~1e-3 relative.
TEST(BoxFilter, RampIsDelayedByHalfTheDuration)
{
  for (double t_s : {260e-6, 125e-6, 123.4e-6, 3.7e-6})
  {
    BoxFilter<1> filter(t_s, kTs);
    const double a = 0.3;                   // offset [rad]
    const double b = 2.0;                   // slope [rad/s]
    filter.reset(BoxFilter<1>::Vector(a));  // at rest at the ramp's start value
    const std::size_t start = static_cast<std::size_t>(std::ceil(t_s / kTs)) + 1;
    for (std::size_t n = 0; n < 5000; ++n)
    {
      const double t = static_cast<double>(n) * kTs;
      filter.push(BoxFilter<1>::Vector(a + b * t));
      if (n < start)
      {
        continue;  // start transient: the window still reaches before the ramp's start
      }
      const double expected = a + b * (t - 0.5 * t_s);
      ASSERT_NEAR(filter.average()(0), expected, 1e-12 * std::abs(expected)) << "T = " << t_s << ", n = " << n;
      // exact derivative = slope; 1e-9 relative: (x_n − x(t_n − T))/T loses ~|x|/(b·T) digits
      ASSERT_NEAR(filter.derivative()(0), b, 1e-9 * b) << "T = " << t_s << ", n = " << n;
      ASSERT_NEAR(filter.delayed()(0), a + b * (t - t_s), 1e-12 * std::abs(expected));
    }
  }
}

// The output is the exact mean of the piecewise-linear input over [t_n − T, t_n], checked on a
// seeded random signal against an independent piecewise integration. Tolerance 1e-12 absolute
// on O(1) values (rounding only).
TEST(BoxFilter, MatchesExactIntegralOfLinearInterpolation)
{
  std::mt19937 rng(12345);
  std::uniform_real_distribution<double> dist(-1.0, 1.0);
  std::vector<double> x(400);
  for (double& v : x)
  {
    v = dist(rng);
  }
  for (double t_s : {260e-6, 125e-6, 123.4e-6, 3.7e-6, 10e-6, 0.0})
  {
    BoxFilter<1> filter(t_s, kTs);
    filter.reset(BoxFilter<1>::Vector(x[0]));
    for (std::size_t n = 0; n < x.size(); ++n)
    {
      filter.push(BoxFilter<1>::Vector(x[n]));
      const double t = static_cast<double>(n) * kTs;
      const double expected = (t_s == 0.0) ? x[n] : exactMean(x, t - t_s, t);
      ASSERT_NEAR(filter.average()(0), expected, 1e-12) << "T = " << t_s << ", n = " << n;
    }
  }
}

// Unit DC gain: a constant comes out unchanged once the window is full. 1e-15 relative: the
// taps are normalised by (m + f), the sum of 28 terms rounds at ~1e-16 each.
TEST(BoxFilter, UnitDcGainAndRestBeforeStart)
{
  for (double t_s : {260e-6, 125e-6, 123.4e-6, 0.0})
  {
    BoxFilter<2> filter(t_s, kTs);
    const Eigen::Vector2d rest(-0.05, 0.07);
    filter.reset(rest);
    // before any new sample the input is held at the rest value: output = rest
    filter.push(rest);
    EXPECT_NEAR(filter.average()(0), rest(0), 1e-15 * std::abs(rest(0)));
    EXPECT_EQ(filter.derivative()(0), 0.0);
    const Eigen::Vector2d level(0.123, -0.456);
    for (std::size_t n = 0; n < filter.taps() + 1; ++n)
    {
      filter.push(level);
    }
    EXPECT_NEAR(filter.average()(0), level(0), 1e-15 * std::abs(level(0))) << "T = " << t_s;
    EXPECT_NEAR(filter.average()(1), level(1), 1e-15 * std::abs(level(1))) << "T = " << t_s;
    EXPECT_EQ(filter.derivative()(0), 0.0);
    // ring size: ceil(T/Ts) + 2 at most
    EXPECT_LE(filter.taps(), static_cast<std::size_t>(std::ceil(t_s / kTs - 1e-9)) + 2);
  }
}

TEST(BoxFilter, RejectsBadDurations)
{
  EXPECT_THROW(BoxFilter<1>(-1e-6, kTs), scanhead::ConfigError);
  EXPECT_THROW(BoxFilter<1>(std::nan(""), kTs), scanhead::ConfigError);
  EXPECT_THROW(BoxFilter<1>(1e-4, 0.0), scanhead::ConfigError);
  EXPECT_NO_THROW(BoxFilter<1>(0.0, kTs));
}

namespace
{
/// Length of [lo, hi] ∩ [a, b].
double overlap(double lo, double hi, double a, double b)
{
  return std::max(0.0, std::min(hi, b) - std::max(lo, a));
}
}  // namespace

// A velocity step of one axis, through FIR T1 then FIR T2 as in the NC: the acceleration of
// Q_filt1 is a rectangle of width T1 and height v/T1, that of Q_filt2 a trapezoid with ramps of
// T2 (the box T2 applied to that rectangle). The step starts at a sample and T1 = 260 µs is a
// whole number of samples, so Q_filt1's velocity is piecewise linear with kinks on samples and
// the exact derivatives must match the analytic shapes to rounding (1e-9 of the plateau); with
// T1 = 263.7 µs the kink falls between samples and the measured widths are checked to one sample.
TEST(BoxFilter, VelocityStepGivesRectangleThenTrapezoidAcceleration)
{
  const double v = 3.0;  // velocity step [rad/s]
  const std::size_t n0 = 50;
  const double t0 = static_cast<double>(n0) * kTs;
  for (double t1 : {260e-6, 263.7e-6})
  {
    const double t2 = 125e-6;
    BoxFilter<1> fir1(t1, kTs);
    BoxFilter<2> fir2(t2, kTs);
    fir1.reset(BoxFilter<1>::Vector(0.0));
    fir2.reset(Eigen::Vector2d::Zero());
    const double plateau = v / t1;
    double prev_v1 = 0.0;
    std::size_t rect_samples = 0;  // samples of acc1 at the plateau (full period inside)
    double rect_area = 0.0;        // ∫acc1 dt
    std::size_t trap_support = 0;  // samples with acc2 > 0
    std::size_t trap_plateau = 0;  // samples with acc2 at the plateau
    double max_err_exact = 0.0;
    for (std::size_t n = 0; n < 200; ++n)
    {
      const double t = static_cast<double>(n) * kTs;
      const double x = n > n0 ? v * (t - t0) : 0.0;
      fir1.push(BoxFilter<1>::Vector(x));
      const double v1 = fir1.derivative()(0);
      const double acc1 = (v1 - prev_v1) / kTs;  // mean acceleration over [t_{n−1}, t_n]
      prev_v1 = v1;
      fir2.push(Eigen::Vector2d(fir1.average()(0), v1));
      const double acc2 = fir2.derivative()(1);
      rect_area += acc1 * kTs;
      if (std::abs(acc1 - plateau) < 1e-9 * plateau)
      {
        ++rect_samples;
      }
      if (acc2 > 1e-9 * plateau)
      {
        ++trap_support;
      }
      if (std::abs(acc2 - plateau) < 1e-9 * plateau)
      {
        ++trap_plateau;
      }
      if (t1 == 260e-6)
      {
        const double acc1_exact = plateau * overlap(t - kTs, t, t0, t0 + t1) / kTs;
        const double acc2_exact = plateau * overlap(t - t2, t, t0, t0 + t1) / t2;
        max_err_exact = std::max(max_err_exact, std::abs(acc1 - acc1_exact));
        max_err_exact = std::max(max_err_exact, std::abs(acc2 - acc2_exact));
      }
    }
    // the rectangle: area v, plateau v/T1 → width = area/height = T1; whole plateau samples = floor(T1/Ts)
    EXPECT_NEAR(rect_area / plateau, t1, 1e-9 * t1);
    EXPECT_NEAR(static_cast<double>(rect_samples), std::floor(t1 / kTs + 1e-9), 1.0);
    // the trapezoid: support T1 + T2, plateau T1 − T2 (ramps of T2 each), to one sample
    EXPECT_NEAR(static_cast<double>(trap_support) * kTs, t1 + t2, kTs + 1e-12);
    EXPECT_NEAR(static_cast<double>(trap_plateau) * kTs, t1 - t2, kTs + 1e-12);
    EXPECT_LT(max_err_exact, 1e-9 * plateau) << "T1 = " << t1;
  }
}

// Velocity saturation: |Δs| <= v_max·Ts per axis, velocity clamped, unlimited axes pass through.
TEST(RateLimiter, LimitsStepPerAxisAndCarriesVelocity)
{
  scanhead::RateLimiter limiter(25.0, kTs);
  limiter.reset(Eigen::Vector2d::Zero());
  Eigen::Vector2d s;
  Eigen::Vector2d s_dot;
  // axis x asks for 1 rad at once: moves 25e-5 rad per sample; axis y a small move passes
  EXPECT_TRUE(limiter.step(Eigen::Vector2d(1.0, 1e-5), Eigen::Vector2d(30.0, 1.0), s, s_dot));
  EXPECT_DOUBLE_EQ(s(0), 25.0 * kTs);
  EXPECT_EQ(s(1), 1e-5);
  EXPECT_EQ(s_dot(0), 25.0);
  EXPECT_EQ(s_dot(1), 1.0);
  EXPECT_TRUE(limiter.step(Eigen::Vector2d(-1.0, 2e-5), Eigen::Vector2d(-30.0, 1.0), s, s_dot));
  EXPECT_NEAR(s(0), 0.0, 1e-18);
  EXPECT_EQ(s_dot(0), -25.0);
  EXPECT_FALSE(limiter.step(Eigen::Vector2d(1e-4, 3e-5), Eigen::Vector2d(40.0, 1.0), s, s_dot));
  EXPECT_EQ(s(0), 1e-4);
  EXPECT_EQ(s_dot(0), 25.0);  // velocity clamped even when the step passes
  EXPECT_THROW(scanhead::RateLimiter(0.0, kTs), scanhead::ConfigError);
}

TEST(BoxFilter, PushBlockIsPushAverageDerivativeBitForBit)
{
  // The NC filters a chunk at a time: every output of pushBlock must be the bits of push() then
  // average() / derivative() sample by sample, for whole and fractional durations, the identity,
  // blocks shorter and longer than the window, and only the first average_channels averages.
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> step(-1e-3, 1e-3);
  for (const double duration_s : {0.0, 0.3 * kTs, 2.6 * kTs, 260e-6})
  {
    BoxFilter<4> block(duration_s, kTs);
    BoxFilter<4> single(duration_s, kTs);
    const Eigen::Vector4d start(0.1, -0.2, 0.0, 3.0);
    block.reset(start);
    single.reset(start);
    Eigen::Vector4d x = start;
    for (const std::size_t count : {1, 7, 1000, 3, 40, 1})
    {
      std::vector<Eigen::Vector4d> in(count), average(count, Eigen::Vector4d::Constant(-7.0)), derivative(count);
      for (Eigen::Vector4d& v : in)
      {
        x += Eigen::Vector4d(step(rng), step(rng), step(rng), step(rng));
        v = x;
      }
      const int channels = count == 40 ? 2 : 4;
      block.pushBlock(in.data(), count, average.data(), derivative.data(), channels);
      for (std::size_t i = 0; i < count; ++i)
      {
        single.push(in[i]);
        const Eigen::Vector4d a = single.average();
        const Eigen::Vector4d d = single.derivative();
        for (int c = 0; c < 4; ++c)
        {
          if (c < channels)
          {
            ASSERT_EQ(average[i][c], a[c]) << "T " << duration_s << " count " << count << " sample " << i;
          }
          else
          {
            ASSERT_EQ(average[i][c], -7.0);  // not written
          }
          ASSERT_EQ(derivative[i][c], d[c]) << "T " << duration_s << " count " << count << " sample " << i;
        }
      }
      for (std::size_t k = 0; k < single.taps(); ++k)
      {
        ASSERT_EQ(block.sampleAgo(k), single.sampleAgo(k)) << "window after the block, k " << k;
      }
    }
  }
}
