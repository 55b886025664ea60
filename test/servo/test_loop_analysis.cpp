/// \file test_loop_analysis.cpp
/// \brief Loop figures of the default galvos against the THESIS targets, the synthesis that made the
/// gains, and the analytic bandwidth against a sine sweep of the time-domain model.
#include <gtest/gtest.h>

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <complex>
#include <iostream>
#include <string>

#include "scanhead/common/errors.hpp"
#include "scanhead/servo/cascade_axis.hpp"
#include "scanhead/servo/loop_analysis.hpp"

namespace scanhead
{
namespace
{
constexpr double kPi = 3.14159265358979323846;
constexpr double kTs = 1e-5;

/// \brief |θ/θref| of the time-domain CascadeAxis at \p f_hz: sine of 1e-3 rad with its exact
/// derivatives, projection over whole periods after the slow position pole (≈ Kθ, 31 ms for Y) has
/// decayed (0.3 s: e^{-9}).
std::complex<double> simulatedResponse(const AxisLoopConfig& cfg, double f_hz, bool voltage_ff = true)
{
  CascadeAxis axis(cfg, kTs, 1.0 / kTs, false, voltage_ff);
  axis.reset(0.0);
  const double w = 2 * kPi * f_hz, amp = 1e-3;
  const int settle = 30000;
  const int periods = static_cast<int>(std::ceil(0.02 * f_hz));
  std::complex<double> y(0), u(0);
  // whole number of periods: choose the count of samples closest to periods/f, then project both signals
  const int n = static_cast<int>(std::lround(periods / (f_hz * kTs)));
  for (int k = 0; k < settle + n; ++k)
  {
    const double t = k * kTs;
    const double ref = amp * std::sin(w * t);
    const AxisModel::Output o = axis.step(ref, amp * w * std::cos(w * t), -amp * w * w * std::sin(w * t));
    if (k >= settle)
    {
      const std::complex<double> e = std::exp(std::complex<double>(0.0, -w * t));
      y += o.position * e;
      u += ref * e;
    }
  }
  return y / u;
}

AxisLoopConfig linearised(const AxisLoopConfig& c, bool feedforward)
{
  AxisLoopConfig l = c;
  l.plant.offset_torque_nm = 0.0;
  l.plant.coulomb_torque_nm = 0.0;
  if (!feedforward)
    l.gains.k1 = l.gains.k2 = 0.0;
  return l;
}
}  // namespace

// THESIS §2.2.2.2 targets (SPEC §3) at the default 100 kHz controller, sampling delay included.
// Tolerances: crossovers within 10 % of the target, the position margin within 5° of 75°, the inner
// margins ≥ 65° less 0.05° (the stored gains are rounded to 6 digits); Y bandwidth (feedback only,
// as THESIS Fig. 2.40) within 15 % of 1 kHz, X's higher.
TEST(LoopAnalysis, DefaultGalvosMeetTheThesisTargets)
{
  const ServoConfig c;
  const double tc = 1.0 / c.controller_rate_hz;
  const LoopReport y = analyseLoops(c.y.plant, c.y.gains, tc);
  const LoopReport x = analyseLoops(c.x.plant, c.x.gains, tc);
  const double k = kGalvoXCrossoverScale;
  for (const auto& [r, s] : {std::make_pair(y, 1.0), std::make_pair(x, k)})
  {
    EXPECT_NEAR(r.position.crossover_rad_s, 3000.0 * s, 300.0 * s);
    EXPECT_NEAR(r.position.phase_margin_deg, 75.0, 5.0);
    EXPECT_NEAR(r.speed.crossover_rad_s, 5000.0 * s, 500.0 * s);
    EXPECT_GE(r.speed.phase_margin_deg, 64.95);
    EXPECT_NEAR(r.current.crossover_rad_s, 1e4 * s, 1e3 * s);
    EXPECT_GE(r.current.phase_margin_deg, 64.95);
  }
  EXPECT_NEAR(y.bandwidth_hz, 1000.0, 150.0);
  EXPECT_GT(x.bandwidth_hz, y.bandwidth_hz);
  // the feedforward's ramp lag is 0 to first order (θ/θref = 1 + O(s²))
  EXPECT_LT(std::abs(y.low_frequency_delay_s), 1e-9);
  std::cout << "[ info ] Y: bw " << y.bandwidth_hz << " Hz (with FF " << y.bandwidth_with_feedforward_hz << " Hz, peak "
            << y.peak_with_feedforward_db << " dB); crossovers/margins i " << y.current.crossover_rad_s << "/"
            << y.current.phase_margin_deg << ", w " << y.speed.crossover_rad_s << "/" << y.speed.phase_margin_deg
            << ", theta " << y.position.crossover_rad_s << "/" << y.position.phase_margin_deg << "\n";
  std::cout << "[ info ] X: bw " << x.bandwidth_hz << " Hz (with FF " << x.bandwidth_with_feedforward_hz << " Hz, peak "
            << x.peak_with_feedforward_db << " dB); crossovers/margins i " << x.current.crossover_rad_s << "/"
            << x.current.phase_margin_deg << ", w " << x.speed.crossover_rad_s << "/" << x.speed.phase_margin_deg
            << ", theta " << x.position.crossover_rad_s << "/" << x.position.phase_margin_deg << "\n";
  const LoopReport y20 = analyseLoops(c.y.plant, c.y.gains, 5e-5);
  std::cout << "[ info ] Y at 20 kHz: bw " << y20.bandwidth_hz << " Hz, margins i " << y20.current.phase_margin_deg
            << ", w " << y20.speed.phase_margin_deg << ", theta " << y20.position.phase_margin_deg << "\n";
}

// The stored gains are what synthesiseGains() gives for the stored plants with the THESIS's refined
// Tiω (6-digit rounding: 1e-5 relative), and the synthesis hits its own targets exactly (1e-6
// relative, 1e-4°); the given Tiω leaves the speed loop more than its 65° (THESIS rule).
TEST(LoopAnalysis, StoredGainsAreTheSynthesis)
{
  const ServoConfig c;
  const double tc = 1.0 / c.controller_rate_hz;
  const std::pair<const AxisLoopConfig*, double> axes[2] = {{&c.x, kGalvoXCrossoverScale}, {&c.y, 1.0}};
  for (const auto& [a, scale] : axes)
  {
    const LoopTargets t = storedGainTargets().scaled(scale);
    const CascadeGains g = synthesiseGains(a->plant, t, tc);
    EXPECT_NEAR(g.kii, a->gains.kii, 1e-5 * g.kii);
    EXPECT_NEAR(g.tii_s, a->gains.tii_s, 1e-5 * g.tii_s);
    EXPECT_NEAR(g.kiw, a->gains.kiw, 1e-5 * g.kiw);
    EXPECT_NEAR(g.tiw_s, a->gains.tiw_s, 1e-5 * g.tiw_s);
    EXPECT_NEAR(g.ktheta, a->gains.ktheta, 1e-5 * g.ktheta);
    EXPECT_NEAR(g.tdtheta_s, a->gains.tdtheta_s, 1e-5 * g.tdtheta_s);
    const LoopReport r = analyseLoops(a->plant, g, tc);
    EXPECT_NEAR(r.current.crossover_rad_s, t.current_crossover_rad_s, 1e-6 * t.current_crossover_rad_s);
    EXPECT_NEAR(r.speed.crossover_rad_s, t.speed_crossover_rad_s, 1e-6 * t.speed_crossover_rad_s);
    EXPECT_GE(r.speed.phase_margin_deg, t.speed_margin_deg);
    EXPECT_NEAR(g.tiw_s, kThesisSpeedIntegralTime_s / scale, 1e-12);
    EXPECT_NEAR(r.position.crossover_rad_s, t.position_crossover_rad_s, 1e-6 * t.position_crossover_rad_s);
    EXPECT_NEAR(r.position.phase_margin_deg, t.position_margin_deg, 1e-4);
  }
}

// Without a given Tiω the speed PI's integral time comes from its margin rule and hits 65° exactly;
// a given Tiω that would leave less than that is refused.
TEST(LoopAnalysis, SpeedIntegralTimeFromTheMarginOrGiven)
{
  const ServoConfig c;
  const double tc = 1.0 / c.controller_rate_hz;
  const LoopTargets rule;  // speed_integral_time_s = 0
  const CascadeGains g = synthesiseGains(c.y.plant, rule, tc);
  const LoopReport r = analyseLoops(c.y.plant, g, tc);
  EXPECT_NEAR(r.speed.phase_margin_deg, rule.speed_margin_deg, 1e-4);
  EXPECT_LT(g.tiw_s, kThesisSpeedIntegralTime_s);  // the rule's Tiω is shorter than the THESIS's refined one
  LoopTargets too_short = rule;
  too_short.speed_integral_time_s = 0.5 * g.tiw_s;
  EXPECT_THROW(synthesiseGains(c.y.plant, too_short, tc), NumericalError);
}

// The analytic −3 dB bandwidth (feedback only) agrees with a sine sweep of the time-domain model
// (plant + discrete controller at 100 kHz, friction off since the analysis is linear) within 3 %:
// |T| measured at the analytic bandwidth and ±3 % of it must bracket −3 dB, and the crossing
// interpolated in dB lies within 3 %. The measured gain at 300 Hz and 1 kHz with the feedforward
// also equals the analytic eq. 2.32 within 3 % (the feedforward paths are implemented as analysed).
TEST(LoopAnalysis, AnalyticBandwidthMatchesSimulatedSweep)
{
  const ServoConfig c;
  for (const AxisLoopConfig* a : {&c.x, &c.y})
  {
    const AxisLoopConfig fb = linearised(*a, false);
    const CascadeLoops loops(fb.plant, fb.gains, kTs);
    const double bw = closedLoopBandwidth(loops, false);
    double f_prev = 0.0, db_prev = 0.0, crossing = 0.0;
    for (double r : {0.97, 1.0, 1.03})
    {
      const double f = r * bw;
      const double db = 20 * std::log10(std::abs(simulatedResponse(fb, f)));
      std::cout << "[ info ] " << f << " Hz: simulated " << db << " dB, analytic "
                << 20 * std::log10(std::abs(loops.closedLoop(2 * kPi * f, false))) << " dB\n";
      if (f_prev > 0.0 && db_prev >= -3.0103 && db < -3.0103)
        crossing = f_prev + (f - f_prev) * (-3.0103 - db_prev) / (db - db_prev);
      f_prev = f;
      db_prev = db;
    }
    ASSERT_GT(crossing, 0.0) << "no -3 dB crossing within ±3 % of the analytic bandwidth " << bw;
    EXPECT_NEAR(crossing, bw, 0.03 * bw);
    const AxisLoopConfig ff = linearised(*a, true);
    const CascadeLoops loops_ff(ff.plant, ff.gains, kTs);
    for (double f : {300.0, 1000.0})
    {
      const double sim = std::abs(simulatedResponse(ff, f));
      const double model = std::abs(loops_ff.closedLoop(2 * kPi * f, true));
      EXPECT_NEAR(sim, model, 0.03 * model) << f << " Hz";
    }
    std::cout << "[ info ] bandwidth analytic " << bw << " Hz, simulated sweep " << crossing << " Hz ("
              << 100.0 * (crossing / bw - 1.0) << " %)\n";
  }
}

// Voltage feedforward (servo.voltage_feedforward, default on) against the pure THESIS structure:
// the feedback-only figures are identical (it is not in any loop: exact equality), the ramp lag
// stays 0 to first order (1e-9 s), the with-feedforward peak drops by more than 2 dB (Y: +6.95 →
// +4.27 dB, X: +7.23 → +3.74 dB) and |1 − θ/θref| stays below 10 % up to 1 kHz (Y: 8.7 % at 1 kHz),
// where the THESIS structure is far off (|1 − θ/θref| at 1 kHz: Y 0.99, X 0.46; asserted > 0.3). The time-domain model
// with it off equals the analytic THESIS eq. 2.32 at 300 Hz and 1 kHz within 3 % (as the sweep test with it on).
TEST(LoopAnalysis, VoltageFeedforward)
{
  const ServoConfig c;
  for (const AxisLoopConfig* a : {&c.x, &c.y})
  {
    const LoopReport on = analyseLoops(a->plant, a->gains, kTs, true);
    const LoopReport off = analyseLoops(a->plant, a->gains, kTs, false);
    EXPECT_EQ(on.bandwidth_hz, off.bandwidth_hz);
    EXPECT_EQ(on.current.phase_margin_deg, off.current.phase_margin_deg);
    EXPECT_EQ(on.speed.phase_margin_deg, off.speed.phase_margin_deg);
    EXPECT_EQ(on.position.phase_margin_deg, off.position.phase_margin_deg);
    EXPECT_LT(std::abs(on.low_frequency_delay_s), 1e-9);
    EXPECT_LT(on.peak_with_feedforward_db, off.peak_with_feedforward_db - 2.0);
    const CascadeLoops loops_on(a->plant, a->gains, kTs, true);
    const CascadeLoops loops_off(a->plant, a->gains, kTs, false);
    for (double f = 10.0; f <= 1000.0; f *= 1.1)
      EXPECT_LT(std::abs(1.0 - loops_on.closedLoop(2 * kPi * f, true)), 0.10) << f << " Hz";
    EXPECT_GT(std::abs(1.0 - loops_off.closedLoop(2 * kPi * 1000.0, true)), 0.3);
    std::cout << "[ info ] peak with feedforward " << on.peak_with_feedforward_db << " dB (THESIS structure "
              << off.peak_with_feedforward_db << " dB), bandwidth " << on.bandwidth_with_feedforward_hz << " Hz ("
              << off.bandwidth_with_feedforward_hz << " Hz)\n";
    const AxisLoopConfig ff = linearised(*a, true);
    const CascadeLoops lin_off(ff.plant, ff.gains, kTs, false);
    for (double f : {300.0, 1000.0})
    {
      const double sim = std::abs(simulatedResponse(ff, f, false));
      const double model = std::abs(lin_off.closedLoop(2 * kPi * f, true));
      EXPECT_NEAR(sim, model, 0.03 * model) << f << " Hz";
    }
  }
}

// The flexible mode shows in the analysed plant response at its configured frequency.
TEST(LoopAnalysis, ModeAtConfiguredFrequency)
{
  const ServoConfig c;
  for (const AxisLoopConfig* a : {&c.x, &c.y})
  {
    const LoopReport r = analyseLoops(a->plant, a->gains, kTs);
    EXPECT_NEAR(r.mode_frequency_hz, a->plant.mode_frequency_hz, 1e-3 * a->plant.mode_frequency_hz);
  }
}

// The report the tool prints: YAML with the required keys, equal to analyseLoops().
TEST(LoopAnalysis, ReportYaml)
{
  const ServoConfig c;
  const YAML::Node y = YAML::Load(loopsReportYaml(c, 1));
  for (const char* key :
       {"bandwidth_hz", "position_crossover_rad_s", "position_phase_margin_deg", "speed_crossover_rad_s",
        "speed_phase_margin_deg", "current_crossover_rad_s", "current_phase_margin_deg",
        "bandwidth_with_feedforward_hz", "low_frequency_delay_s", "mode_frequency_hz"})
    EXPECT_TRUE(y[key].IsDefined()) << key;
  const LoopReport r = analyseLoops(c.y.plant, c.y.gains, 1.0 / c.controller_rate_hz);
  EXPECT_NEAR(y["bandwidth_hz"].as<double>(), r.bandwidth_hz, 1e-5 * r.bandwidth_hz);
  EXPECT_EQ(y["axis"].as<std::string>(), "y");
  EXPECT_THROW(loopsReportYaml(c, 2), ConfigError);
}
}  // namespace scanhead
