/// \file test_cascade_axis.cpp
/// \brief The cascade axis in the time domain: ramp lag vs the analytic low-frequency delay, hold at
/// rest, large steps under saturation, controller rates, factory and validation.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <string>

#include "scanhead/common/errors.hpp"
#include "scanhead/servo/cascade_axis.hpp"
#include "scanhead/servo/loop_analysis.hpp"

namespace scanhead
{
namespace
{
constexpr double kTs = 1e-5;

/// \brief Following error θref − θ after a ramp of slope \p v [rad/s] from rest for \p seconds.
double rampError(const AxisLoopConfig& cfg, double rate_hz, double v, double seconds, bool differentiate = false)
{
  CascadeAxis axis(cfg, kTs, rate_hz, differentiate);
  axis.reset(0.0);
  const long n = std::lround(seconds / kTs);
  AxisModel::Output o;
  double ref = 0.0;
  for (long k = 0; k < n; ++k)
  {
    ref = v * k * kTs;
    o = axis.step(ref, v, 0.0);
  }
  return ref - o.position;
}
}  // namespace

// Without feedforward (K1 = K2 = 0) and friction, a ramp's steady following error is v × the
// analytic low-frequency delay −d arg(θ/θref)/dω|0 (≈ 1/Kθ = 31 ms for Y; the slow closed-loop pole
// near Kθ/(1 + 1.01 Kθ Tdθ) ≈ 9/s decays in 2 s to e^{-18}): within 0.5 % (the residual transient and the discrete
// controller's O(T) lag). With the feedforward (defaults, friction included) the lag vanishes: the error is below 1e-4
// × v × (1/Kθ) and the analytic delay is 0 to 1e-9 s.
TEST(CascadeAxis, RampLagEqualsLowFrequencyDelay)
{
  const ServoConfig c;
  AxisLoopConfig fb = c.y;
  fb.gains.k1 = fb.gains.k2 = 0.0;
  fb.plant.offset_torque_nm = fb.plant.coulomb_torque_nm = 0.0;
  const double v = 1.0;
  const double delay = CascadeAxis(fb, kTs, 1e5, false).lowFrequencyDelay();
  const double err = rampError(fb, 1e5, v, 2.0);
  EXPECT_NEAR(err, v * delay, 0.005 * v * delay);
  const CascadeAxis ff(c.y, kTs, 1e5, false);
  EXPECT_LT(std::abs(ff.lowFrequencyDelay()), 1e-9);
  const double err_ff = rampError(c.y, 1e5, v, 0.3);
  EXPECT_LT(std::abs(err_ff), 1e-4 * v / c.y.gains.ktheta);
  std::cout << "[ info ] Y ramp 1 rad/s: lag without feedforward " << err << " rad (v x delay " << v * delay
            << "), with feedforward " << err_ff << " rad\n";
}

// A constant setpoint at the reset position: nothing moves (no drive, the rotor stays stuck;
// 1e-15 rad). An unreset axis starts at rest at its first setpoint.
TEST(CascadeAxis, HoldsAtRest)
{
  const ServoConfig c;
  CascadeAxis axis(c.x, kTs, 1e5, false);
  axis.reset(0.1234);
  for (int k = 0; k < 2000; ++k)
  {
    const AxisModel::Output o = axis.step(0.1234, 0.0, 0.0);
    ASSERT_NEAR(o.position, 0.1234, 1e-15);
    ASSERT_EQ(o.current, 0.0);
  }
  CascadeAxis fresh(c.y, kTs, 1e5, false);
  EXPECT_EQ(fresh.step(-0.2, 0.0, 0.0).position, -0.2);
}

// A raw 0.3 rad step (no NC filter): the voltage saturates at the supply, the anti-windup keeps the
// response bounded (overshoot < 30 %), and it settles (|error| < 1 % after 1 s: the class-0 loop's
// slow pole ≈ 9/s); the reported current is the plant's.
TEST(CascadeAxis, LargeStepSaturatesAndSettles)
{
  const ServoConfig c;
  CascadeAxis axis(c.y, kTs, 1e5, false);
  axis.reset(0.0);
  double peak = 0.0, vmax = 0.0;
  AxisModel::Output o;
  for (int k = 0; k < 100000; ++k)
  {
    o = axis.step(0.3, 0.0, 0.0);
    peak = std::max(peak, o.position);
    vmax = std::max(vmax, std::abs(axis.plant().lastVoltage()));
    ASSERT_EQ(o.current, o.current);  // finite
  }
  EXPECT_EQ(vmax, c.y.plant.supply_voltage_v);
  EXPECT_LT(peak, 0.39);
  EXPECT_NEAR(o.position, 0.3, 3e-3);
  const double i_now = axis.plant().current();
  EXPECT_EQ(axis.step(0.3, 0.0, 0.0).current, i_now);
  std::cout << "[ info ] Y raw 0.3 rad step: overshoot " << 100.0 * (peak / 0.3 - 1.0) << " %, after 1 s error "
            << 0.3 - o.position << " rad, peak |U| " << vmax << " V"
            << "\n";
}

// Controller rates: the bench's 20 kHz (every 5th sample) and 200 kHz (two instants per sample)
// track a smooth 200 Hz sine (with its derivatives) about as well as 100 kHz: tracking error rms
// within a factor 3 of the 100 kHz one, all far below the amplitude (< 2 %); a rate that is neither
// a multiple nor a fraction of the sample rate is refused naming the key.
TEST(CascadeAxis, ControllerRates)
{
  const ServoConfig c;
  auto rms = [&](double rate, bool differentiate) {
    CascadeAxis axis(c.y, kTs, rate, differentiate);
    axis.reset(0.0);
    const double w = 2 * 3.14159265358979 * 200.0, amp = 0.01;
    double sum = 0.0;
    int n = 0;
    for (int k = 0; k < 20000; ++k)
    {
      const double t = k * kTs;
      const AxisModel::Output o =
          axis.step(amp * (1 - std::cos(w * t)), amp * w * std::sin(w * t), amp * w * w * std::cos(w * t));
      if (k >= 10000)
      {
        sum += std::pow(amp * (1 - std::cos(w * t)) - o.position, 2);
        ++n;
      }
    }
    return std::sqrt(sum / n);
  };
  const double e100 = rms(1e5, false), e20 = rms(2e4, false), e200 = rms(2e5, false), ediff = rms(1e5, true);
  EXPECT_LT(e100, 0.02 * 0.01);
  EXPECT_LT(e20, 3.0 * e100 + 1e-7);
  EXPECT_LT(e200, 3.0 * e100 + 1e-7);
  EXPECT_LT(ediff, 3.0 * e100 + 1e-7);
  std::cout << "[ info ] 200 Hz sine, rms error [rad]: 100 kHz " << e100 << ", 20 kHz " << e20 << ", 200 kHz " << e200
            << ", differentiating feedforward " << ediff << "\n";
  try
  {
    CascadeAxis bad(c.y, kTs, 3e4, false);
    FAIL() << "30 kHz accepted with 10 us samples";
  }
  catch (const ConfigError& e)
  {
    EXPECT_NE(std::string(e.what()).find("servo.controller_rate_hz"), std::string::npos) << e.what();
  }
}

// The factory: cascade by default, the simple model when selected, errors named.
TEST(CascadeAxis, FactoryAndValidation)
{
  ServoConfig c;
  EXPECT_EQ(c.model, "cascade");
  EXPECT_NE(dynamic_cast<CascadeAxis*>(makeAxisModel(c, 0, kTs).get()), nullptr);
  EXPECT_NEAR(axisLowFrequencyDelay(*makeAxisModel(c, 1, kTs)), 0.0, 1e-9);
  c.model = "closed_loop_3rd_order";
  EXPECT_NE(dynamic_cast<ClosedLoopAxis*>(makeAxisModel(c, 1, kTs).get()), nullptr);
  EXPECT_THROW(makeAxisModel(c, 2, kTs), ConfigError);
  c = ServoConfig();
  c.y.gains.kii = -1.0;
  try
  {
    makeAxisModel(c, 0, kTs);
    FAIL();
  }
  catch (const ConfigError& e)
  {
    EXPECT_EQ(std::string(e.what()), "servo.y.gains.kii must be > 0 (got -1)");
  }
  c = ServoConfig();
  c.x.plant.mode_damping = 0.0;
  EXPECT_THROW(c.validate(), ConfigError);
  c = ServoConfig();
  c.feedforward_derivatives = "guess";
  EXPECT_THROW(c.validate(), ConfigError);
  c = ServoConfig();
  c.controller_rate_hz = 0.0;
  EXPECT_THROW(c.validate(), ConfigError);
}
}  // namespace scanhead
