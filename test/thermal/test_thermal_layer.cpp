/// \file test_thermal_layer.cpp
/// \brief 2D thermal model of the layer (PATH eq. 5, SPEC §5) against closed forms and invariants.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <iostream>
#include <string>
#include <vector>

#include "fixtures/spot_stream_fixture.hpp"
#include "scanhead/common/errors.hpp"
#include "scanhead/thermal/steady_moving_spot.hpp"
#include "scanhead/thermal/thermal_layer.hpp"

using scanhead::ConfigError;
using scanhead::InputError;
using scanhead::MeltedRaster;
using scanhead::NumericalError;
using scanhead::SpotChunk;
using scanhead::SpotSample;
using scanhead::SteadyMeltPool;
using scanhead::ThermalConfig;
using scanhead::ThermalEnergy;
using scanhead::ThermalLayer;
using scanhead::ThermalStep;
using scanhead::ThermalWindow;

namespace
{
constexpr double kTs = scanhead::test_support::kStreamPeriod_s;  // NC period, 100 kHz

using Stream = scanhead::test_support::SpotStream;

SpotChunk chunkOf(const Stream& s, std::size_t start, std::size_t count)
{
  return s.chunk(start, count);
}

/// \brief Feeds \p s in chunks of \p chunk samples, then finish(); returns every step.
std::vector<ThermalStep> feed(ThermalLayer& layer, const Stream& s, std::size_t chunk, bool finish = true)
{
  std::vector<ThermalStep> steps;
  for (std::size_t start = 0; start < s.pos.size(); start += chunk)
  {
    layer.process(chunkOf(s, start, chunk));
    steps.insert(steps.end(), layer.recentSteps().begin(), layer.recentSteps().end());
  }
  if (finish)
  {
    layer.finish();
    steps.insert(steps.end(), layer.recentSteps().begin(), layer.recentSteps().end());
  }
  return steps;
}

/// \brief Powder with the solid's properties: one material, the constant-property model.
ThermalConfig uniformBed()
{
  ThermalConfig c;
  c.density_powder_kg_m3 = c.density_solid_kg_m3;
  c.heat_capacity_powder_j_kg_k = c.heat_capacity_solid_j_kg_k;
  c.conductivity_powder_w_m_k = c.conductivity_solid_w_m_k;
  return c;
}

/// \brief ∫ h·κ·T dA from the window's arrays, κ from the cell state (independent of the books).
double storedFromWindow(const ThermalWindow& w, const ThermalConfig& c)
{
  double s = 0.0;
  for (std::size_t k = 0; k < w.rise_k.size(); ++k)
    s += (w.solid[k] ? c.kappaMelted() : c.kappaPowder()) * w.rise_k[k];
  return s * c.layer_thickness_m * w.cell_m * w.cell_m;
}

double sumRise(const ThermalWindow& w)
{
  double s = 0.0;
  for (double t : w.rise_k)
    s += t;
  return s;
}

double relErr(double value, double reference)
{
  return std::abs(value - reference) / std::abs(reference);
}

std::string configMessage(const ThermalConfig& c)
{
  try
  {
    c.validate();
  }
  catch (const ConfigError& e)
  {
    return e.what();
  }
  return "no throw";
}
}  // namespace

// ------------------------------------------------------------------------------------------------
// Configuration
// ------------------------------------------------------------------------------------------------
TEST(ThermalConfig, ValidateNamesFieldAndValue)
{
  EXPECT_NO_THROW(ThermalConfig().validate());
  ThermalConfig c;
  c.cell_m = -1.0;
  EXPECT_EQ(configMessage(c), "thermal.cell_m must be > 0 (got -1)");
  c = ThermalConfig();
  c.absorptivity = 1.5;
  EXPECT_EQ(configMessage(c), "thermal.absorptivity must be in (0, 1] (got 1.5)");
  c = ThermalConfig();
  c.conductivity_powder_w_m_k = NAN;
  EXPECT_EQ(configMessage(c), "thermal.conductivity_powder_w_m_k must be > 0 (got nan)");
  c = ThermalConfig();
  c.melt_temperature_k = 300.0;
  EXPECT_EQ(configMessage(c), "thermal.melt_temperature_k must be > thermal.ambient_temperature_k (got 300)");
  c = ThermalConfig();
  c.step_samples = 0;
  EXPECT_EQ(configMessage(c), "thermal.step_samples must be in [1, 1000000] (got 0)");
  c = ThermalConfig();
  c.window_m = 0.5e-3;  // < 2·0.3 mm margin
  EXPECT_EQ(configMessage(c), "thermal.window_m must be > 2·recentre_margin_m + 2·cell_m (got 0.0005)");
  c = ThermalConfig();
  c.cell_m = 50e-6;  // > w = 35 µm
  EXPECT_EQ(configMessage(c), "thermal.cell_m must be <= spot_diameter_m/2 (got 5e-05)");
  c = ThermalConfig();
  c.loss_depth_m = INFINITY;
  EXPECT_EQ(configMessage(c), "thermal.loss_depth_m must be finite (got inf)");
  c = ThermalConfig();
  c.phase_switch = "melt";
  EXPECT_EQ(configMessage(c),
            "thermal.phase_switch: unknown 'melt' (known: keep_temperature, keep_energy, consolidate)");
  c = ThermalConfig();
  c.face_conductivity = "geometric";
  EXPECT_EQ(configMessage(c), "thermal.face_conductivity: unknown 'geometric' (known: arithmetic, harmonic)");
  c = ThermalConfig();
  c.window_m = 0.1;  // 10000 cells a side
  EXPECT_EQ(configMessage(c), "thermal.window_m must be <= 4096·cell_m (got 0.1)");
  c = ThermalConfig();
  c.cell_m = 0.0;
  EXPECT_THROW(ThermalLayer layer(c), ConfigError);
}

// ------------------------------------------------------------------------------------------------
// 1. Energy
// ------------------------------------------------------------------------------------------------

// Spot at rest, default bed (it melts): the books close; stored (from the field) + lost (integrated
// by this test from the field after each step) = absorbed within 1 % (the acceptance); at
// the first step nearly all of it is still stored.
TEST(ThermalLayer, DwellEnergyConservation)
{
  ThermalConfig c;
  c.window_m = 1.5e-3;
  const double power = 60.0;
  const Eigen::Vector2d at(0.4e-3, -0.2e-3);
  Stream s;
  s.dwell(at, 1000, power);  // 10 ms, ~30 loss time constants of the powder
  ThermalLayer layer(c);
  double lost_by_test = 0.0;
  double first_fraction = -1.0, first_t = 0.0;
  const double c_loss = c.lossCoefficient() * c.layer_thickness_m * c.cell_m * c.cell_m;
  for (std::size_t k = 0; k < s.pos.size(); ++k)
  {
    layer.process(chunkOf(s, k, 1));
    for (const ThermalStep& st : layer.recentSteps())
    {
      const ThermalWindow w = layer.window();
      lost_by_test += c_loss * sumRise(w) * st.samples * kTs;  // rectangle rule on the end-of-step field
      if (first_fraction < 0.0)
      {
        first_fraction = storedFromWindow(w, c) / layer.energy().absorbed_j;
        first_t = st.time_s;
      }
    }
  }
  layer.finish();
  const ThermalEnergy e = layer.energy();
  const double absorbed = c.absorptivity * s.commandedEnergy();
  const double stored = storedFromWindow(layer.window(), c);
  std::cout << "[dwell] absorbed " << e.absorbed_j << " J, stored " << e.stored_j << " J, lost " << e.lost_j
            << " J, switch " << e.phase_switch_j << " J, outside " << e.outside_j << ", left " << e.left_window_j
            << ", truncated " << e.truncated_j << ", residual " << e.residual_j() << " J; melted "
            << layer.meltedCellCount() << " cells\n";
  EXPECT_LT(relErr(e.absorbed_j, absorbed), 1e-12);
  EXPECT_LT(relErr(e.stored_j, stored), 1e-12);
  EXPECT_LT(std::abs(e.residual_j()), 1e-10 * absorbed);  // the discrete books close to rounding
  EXPECT_EQ(e.phase_switch_j, 0.0);                       // "consolidate", c_s = c_p: no energy at the switch
  EXPECT_LT(e.outside_j + e.left_window_j + e.truncated_j, 1e-6 * absorbed);  // domain large enough
  EXPECT_GT(layer.meltedCellCount(), 0u);
  const double cons = std::abs(stored + lost_by_test - absorbed) / absorbed;
  std::cout << "[dwell] |stored + lost - absorbed| / absorbed (test's own integration) = " << cons << "\n";
  EXPECT_LT(cons, 0.01);  // issue: 1 %; expected ~(dt/τ)²/24 (the rectangle rule vs the exact split loss)
  // Small t: the loss has removed at most t/τ_powder (τ = κ_p δ²/λ_s, the shortest) of it.
  const double tau_p = c.kappaPowder() / c.lossCoefficient();
  std::cout << "[dwell] t = " << first_t * 1e6 << " us: stored / absorbed = " << first_fraction << " (bound "
            << 1.0 - first_t / tau_p << ")\n";
  EXPECT_LE(first_fraction, 1.0 + 1e-12);
  EXPECT_GE(first_fraction, 1.0 - first_t / tau_p);
}

// One material (no switch effect): with adiabatic edges dE/dt = A·P − E/τ, τ = κδ²/λ_s, whatever the
// conduction, so E(t) = A·P·τ·(1 − e^(−t/τ)). Issue: 1 % of A·P·τ; expected: the source enters at
// the middle of each step between exact half-losses, ≈ dt/(2τ)·e^(−t/τ) early on (< 1e-2), ~(dt/τ)² late.
TEST(ThermalLayer, DwellStoredEnergyClosedForm)
{
  ThermalConfig c = uniformBed();
  c.window_m = 1.5e-3;
  c.step_samples = 1;
  const double power = 20.0;
  const double tau = c.kappaSolid() / c.lossCoefficient();
  Stream s;
  s.dwell(Eigen::Vector2d(0.0, 0.0), 300, power);  // 3 ms = 5 τ
  ThermalLayer layer(c);
  double worst = 0.0;
  for (std::size_t k = 0; k < s.pos.size(); ++k)
  {
    layer.process(chunkOf(s, k, 1));
    for (const ThermalStep& st : layer.recentSteps())
    {
      const double t = st.time_s;
      const double ref = c.absorptivity * power * tau * (1.0 - std::exp(-t / tau));
      worst = std::max(worst, std::abs(layer.energy().stored_j - ref) / (c.absorptivity * power * tau));
    }
  }
  const ThermalEnergy e = layer.energy();
  std::cout << "[dwell-uniform] tau " << tau * 1e3 << " ms; worst |E - E_ref| / (A P tau) = " << worst
            << "; outside + left + truncated = " << e.outside_j + e.left_window_j + e.truncated_j << " J\n";
  EXPECT_LT(worst, 0.01);
  // Solid everywhere spreads further than powder: cells below 1e-3 K at the hot box's edge are dropped.
  EXPECT_LT(e.outside_j + e.left_window_j + e.truncated_j, 1e-5 * e.absorbed_j);
}

// ------------------------------------------------------------------------------------------------
// 2. Steady melt pool against the moving-source solution
// ------------------------------------------------------------------------------------------------

// The reference integral reduces to the K0 point-source solution for a tiny spot.
TEST(ThermalSteadyReference, PointSourceK0)
{
  ThermalConfig c = uniformBed();
  c.spot_diameter_m = 0.2e-6;
  const double p = 100.0, v = 0.8;
  const double lam = c.conductivity_solid_w_m_k, a = lam / c.kappaSolid();
  const double m2 = c.lossCoefficient() / lam;
  const double s = std::sqrt(std::pow(v / (2 * a), 2) + m2);
  const double q = c.absorptivity * p;
  for (const Eigen::Vector2d& x : {Eigen::Vector2d(-200e-6, 30e-6), Eigen::Vector2d(50e-6, 0.0),
                                   Eigen::Vector2d(0.0, 100e-6), Eigen::Vector2d(-600e-6, 0.0)})
  {
    const double rho = x.norm();
    const double k0 =
        q / (2 * M_PI * lam * c.layer_thickness_m) * std::exp(-v * x.x() / (2 * a)) * std::cyl_bessel_k(0.0, rho * s);
    const double t = scanhead::steadyMovingSpotRise(c, p, v, x.x(), x.y());
    std::cout << "[K0] xi " << x.x() * 1e6 << " eta " << x.y() * 1e6 << " um: integral " << t << " K, K0 " << k0
              << " K\n";
    // Spot: (w/ρ)² ≤ 1e-5 relative; quadrature: 1e-7·T_melt = 1.4e-4 K absolute.
    EXPECT_LE(std::abs(t - k0), 1e-4 * k0 + 2e-4);
  }
}

// Straight tracks, one material: the simulated steady length and width against steadyMeltPool, and
// the trends the 2D model predicts (length grows with power; with speed from 0.5 to 1 m/s; but falls
// again by 2 m/s at 150 W, unlike the 3D Rosenthal length; at constant P/v it grows with speed).
TEST(ThermalLayer, SteadyMeltPoolMatchesMovingSourceSolution)
{
  const ThermalConfig c = uniformBed();
  struct Case
  {
    double p, v;
    SteadyMeltPool ref;
    double sim_len = 0.0, sim_wid = 0.0;
  };
  std::vector<Case> cases = {{150, 0.5, {}}, {150, 1.0, {}}, {250, 0.5, {}},
                             {250, 1.0, {}}, {150, 2.0, {}}, {125, 0.5, {}}};
  for (Case& k : cases)
  {
    k.ref = scanhead::steadyMeltPool(c, k.p, k.v);
    ThermalConfig cc = c;
    const double length = 3.0e-3;
    cc.settle_time_s = 0.6 * length / k.v;  // the last 40 % of the track: > 3 τ_loss after the start
    ThermalLayer layer(cc);
    Stream s;
    s.line(Eigen::Vector2d(0.0, 3e-6), Eigen::Vector2d(length, 3e-6), k.v, k.p);
    feed(layer, s, 1000);
    k.sim_len = layer.stats().steady_length_mean_m;
    k.sim_wid = layer.stats().steady_width_mean_m;
    std::cout << "[steady] P " << k.p << " W, v " << k.v << " m/s: length predicted " << k.ref.length_m * 1e6
              << " um, simulated " << k.sim_len * 1e6 << " um (" << 100 * (k.sim_len / k.ref.length_m - 1)
              << " %, spread " << layer.stats().steady_length_std_m * 1e6 << " um over " << layer.stats().steady_steps
              << " steps); width " << k.ref.width_m * 1e6 << " / " << k.sim_wid * 1e6 << " um ("
              << 100 * (k.sim_wid / k.ref.width_m - 1) << " %); peak " << k.ref.peak_k << " / "
              << layer.stats().steady_peak_mean_k << " K\n";
    ASSERT_GT(layer.stats().steady_steps, 20u);
    // Grid-limited (10 µm cells, w = 3.5 cells; dt = 2 Ts): measured 0.1–2 %.
    EXPECT_LT(relErr(k.sim_len, k.ref.length_m), 0.05) << "P " << k.p << " v " << k.v;
    EXPECT_LT(relErr(k.sim_wid, k.ref.width_m), 0.05) << "P " << k.p << " v " << k.v;
  }
  auto len = [&](int i, bool sim) { return sim ? cases[i].sim_len : cases[i].ref.length_m; };
  for (bool sim : {false, true})
  {
    EXPECT_GT(len(2, sim), len(0, sim)) << "power, 0.5 m/s, sim " << sim;
    EXPECT_GT(len(3, sim), len(1, sim)) << "power, 1 m/s";
    EXPECT_GT(len(1, sim), len(0, sim)) << "speed, 150 W";
    EXPECT_GT(len(3, sim), len(2, sim)) << "speed, 250 W";
    EXPECT_LT(len(4, sim), len(1, sim)) << "2 m/s, 150 W: shorter again";
    EXPECT_GT(len(3, sim), len(5, sim)) << "P/v = 250 J/m: 1 m/s longer than 0.5 m/s";
  }
}

// ------------------------------------------------------------------------------------------------
// 3. Stability
// ------------------------------------------------------------------------------------------------

// 5 µm cells, dt = Ts: 6.7× the explicit limit cell²/(4a) in the solid (and 67× with dt = 10 Ts).
// Bounded, no undershoot (T ≥ 0 exactly: each 1-D factor is an M-matrix), and the dwell's centre
// approaches the steady solution from below (maximum principle): within 5 % of it at 5 τ with dt = Ts;
// with dt = 10 Ts = 100 µs ≫ w²/(8a) = 37 µs the direction splitting's steady error dt²·AxAy·T
// holds it lower (within 20 %), still bounded and positive.
TEST(ThermalLayer, StableAtLargeDiffusionNumber)
{
  for (std::size_t ns : {std::size_t(1), std::size_t(10)})
  {
    ThermalConfig c = uniformBed();
    c.cell_m = 5e-6;
    c.window_m = 1.2e-3;
    c.step_samples = ns;
    const double a = c.conductivity_solid_w_m_k / c.kappaSolid();
    const double dt = ns * kTs, dt_explicit = c.cell_m * c.cell_m / (4 * a);
    ASSERT_GT(dt, 6.0 * dt_explicit);
    const double power = 20.0;
    const Eigen::Vector2d at(2.5e-6, 2.5e-6);  // a cell centre
    const double steady = scanhead::steadyMovingSpotRise(c, power, 0.0, 0.0, 0.0);
    Stream s;
    s.dwell(at, 300, power);
    s.line(at, Eigen::Vector2d(0.4e-3, 2.5e-6), 1.0, power);
    s.dwell(Eigen::Vector2d(0.4e-3, 2.5e-6), 200, 0.0);
    ThermalLayer layer(c);
    double tmin = 0.0, tmax = 0.0, centre_end = 0.0;
    bool finite = true;
    for (std::size_t k = 0; k < s.pos.size(); k += 5)
    {
      layer.process(chunkOf(s, k, 5));
      const ThermalWindow w = layer.window();
      for (double t : w.rise_k)
      {
        finite = finite && std::isfinite(t);
        tmin = std::min(tmin, t);
        tmax = std::max(tmax, t);
      }
      if (k + 5 == 300)
        centre_end = layer.riseAt(at);
    }
    std::cout << "[stability] dt " << dt * 1e6 << " us = " << dt / dt_explicit << " x explicit limit: T in [" << tmin
              << ", " << tmax << "] K; dwell centre " << centre_end << " K vs steady " << steady << " K\n";
    EXPECT_TRUE(finite);
    EXPECT_GE(tmin, 0.0);
    EXPECT_LE(tmax, steady * 1.001);
    EXPECT_LT(relErr(centre_end, steady), ns == 1 ? 0.05 : 0.20);
  }
}

// ------------------------------------------------------------------------------------------------
// 4. Powder → solid, the global record
// ------------------------------------------------------------------------------------------------

// A track melts a band; the window moves on and forgets it; a later pass over the same line finds it
// solid (from the record) and its pool differs from the first pass's; reset() forgets it.
TEST(ThermalLayer, MeltedCellsStaySolidAndASecondPassSeesThem)
{
  ThermalConfig c;
  const double p = 200.0, v = 1.0, y = 1e-6;
  const double length = 4e-3;
  c.settle_time_s = 1.5e-3;
  Stream pass;
  pass.line(Eigen::Vector2d(0.0, y), Eigen::Vector2d(length, y), v, p);
  Stream both = pass;
  both.line(Eigen::Vector2d(length, y), Eigen::Vector2d(0.0, y), 5.0, 0.0);  // jump back, laser off
  both.dwell(Eigen::Vector2d(0.0, y), 500, 0.0);                             // 5 ms: the bed cools
  const std::size_t second_start = both.pos.size();
  both.pos.insert(both.pos.end(), pass.pos.begin(), pass.pos.end());
  both.power.insert(both.power.end(), pass.power.begin(), pass.power.end());

  ThermalLayer layer(c);
  // First pass.
  feed(layer, pass, 1000, false);
  const scanhead::MeltPoolStats first = layer.stats();
  const double area = layer.meltedArea();
  EXPECT_TRUE(layer.isMelted(Eigen::Vector2d(1e-3, y)));
  EXPECT_TRUE(layer.isMelted(Eigen::Vector2d(0.3e-3, y)));
  EXPECT_FALSE(layer.isMelted(Eigen::Vector2d(1e-3, y + 0.3e-3)));
  const ThermalWindow w1 = layer.window();
  EXPECT_GT(static_cast<double>(w1.origin_i) * c.cell_m, 0.3e-3);  // x = 0.3 mm has left the window
  std::cout << "[switch] pass 1: steady length " << first.steady_length_mean_m * 1e6 << " um, width "
            << first.steady_width_mean_m * 1e6 << " um, peak " << first.steady_peak_mean_k << " K; melted area "
            << area * 1e6 << " mm^2 = " << area / length * 1e6 << " um x track\n";
  // Melted band ≈ track length × pool width (ends: the first w and the last half-pool differ).
  EXPECT_LT(relErr(area / length, first.steady_width_mean_m), 0.10);

  // Second pass, in the same layer.
  Stream rest;
  rest.pos.assign(both.pos.begin() + pass.pos.size(), both.pos.end());
  rest.power.assign(both.power.begin() + pass.power.size(), both.power.end());
  std::size_t start = pass.pos.size();
  bool checked_window = false;
  for (std::size_t k = 0; k < rest.pos.size(); ++k)
  {
    SpotChunk ch = chunkOf(rest, k, 1);
    ch.first_index = start + k;
    layer.process(ch);
    if (!checked_window && start + k == second_start + 5)
    {
      // The window has re-centred on the start of pass 2: x = 0.3 mm is solid before the spot gets there.
      const ThermalWindow w = layer.window();
      const std::int64_t gi = static_cast<std::int64_t>(std::floor(0.3e-3 / c.cell_m));
      const std::int64_t gj = static_cast<std::int64_t>(std::floor(y / c.cell_m));
      ASSERT_GE(gi - w.origin_i, 0);
      ASSERT_LT(gi - w.origin_i, w.width);
      const std::size_t idx = static_cast<std::size_t>(gj - w.origin_j) * w.width + (gi - w.origin_i);
      EXPECT_EQ(w.solid[idx], 1u);
      EXPECT_LT(w.rise_k[idx], 1.0);  // cold: it entered the window at T = 0 and the spot is 0.3 mm away
      checked_window = true;
    }
  }
  layer.finish();
  EXPECT_TRUE(checked_window);
  const scanhead::MeltPoolStats all = layer.stats();
  // Steady means over both passes: recover pass 2's from the sums.
  const double n1 = static_cast<double>(first.steady_steps), n2 = static_cast<double>(all.steady_steps) - n1;
  ASSERT_GT(n2, 20.0);
  const double len2 = (all.steady_length_mean_m * all.steady_steps - first.steady_length_mean_m * n1) / n2;
  const double wid2 = (all.steady_width_mean_m * all.steady_steps - first.steady_width_mean_m * n1) / n2;
  const double pk2 = (all.steady_peak_mean_k * all.steady_steps - first.steady_peak_mean_k * n1) / n2;
  std::cout << "[switch] pass 2 (over solid): steady length " << len2 * 1e6 << " um, width " << wid2 * 1e6
            << " um, peak " << pk2 << " K; melted area " << layer.meltedArea() * 1e6 << " mm^2\n";
  // The consolidated band ahead of the spot conducts 30× better than powder: a cooler, wider pool
  // (measured: peak −7 %, width +4 %, length −2 %); pass 1 repeated on a fresh record is identical (below).
  EXPECT_LT(pk2, 0.97 * first.steady_peak_mean_k);
  EXPECT_GT(wid2, 1.01 * first.steady_width_mean_m);
  // The band was already melted: pass 2 adds little.
  EXPECT_LT(layer.meltedArea(), 1.2 * area);
  EXPECT_TRUE(layer.isMelted(Eigen::Vector2d(1e-3, y)));  // still solid

  // reset() forgets the record: the same pass again gives pass 1 exactly.
  layer.reset();
  feed(layer, pass, 1000, false);
  EXPECT_EQ(layer.stats().steady_length_mean_m, first.steady_length_mean_m);
  EXPECT_EQ(layer.stats().steady_peak_mean_k, first.steady_peak_mean_k);
  EXPECT_EQ(layer.meltedArea(), area);

  // The raster of the record agrees with the count and holds the band.
  const MeltedRaster r = layer.meltedRaster();
  std::uint64_t ones = 0;
  for (std::uint8_t m : r.melted)
    ones += m;
  EXPECT_EQ(ones, r.count);
  EXPECT_EQ(r.count, layer.meltedCellCount());
  EXPECT_NEAR(r.width * c.cell_m, length, 0.1e-3);
}

// "keep_temperature" (PATH read literally) books the energy the switch creates; the books still close.
TEST(ThermalLayer, PhaseSwitchModesKeepTheBooks)
{
  for (const char* mode : {"keep_temperature", "keep_energy", "consolidate"})
  {
    ThermalConfig c;
    c.phase_switch = mode;
    c.window_m = 1.5e-3;
    Stream s;
    s.line(Eigen::Vector2d(0, 0), Eigen::Vector2d(2e-3, 0), 1.0, 200.0);
    ThermalLayer layer(c);
    feed(layer, s, 1000);
    const ThermalEnergy e = layer.energy();
    std::cout << "[modes] " << mode << ": absorbed " << e.absorbed_j << " J, switch " << e.phase_switch_j
              << " J, max length " << layer.stats().max_length_m * 1e6 << " um, residual " << e.residual_j() << " J\n";
    EXPECT_LT(std::abs(e.residual_j()), 1e-10 * e.absorbed_j) << mode;
    if (std::string(mode) == "keep_temperature")
      EXPECT_GT(e.phase_switch_j, 0.05 * e.absorbed_j);  // κ doubles at T > T_melt
    else
      EXPECT_EQ(e.phase_switch_j, 0.0);
  }
}

// ------------------------------------------------------------------------------------------------
// 5. Streaming
// ------------------------------------------------------------------------------------------------
namespace
{
/// \brief Track, corner, laser-off jump, second track (window re-centres several times).
Stream mixedJob()
{
  Stream s;
  s.line(Eigen::Vector2d(0, 0), Eigen::Vector2d(1.2e-3, 0), 1.5, 180.0);
  s.line(Eigen::Vector2d(1.2e-3, 0), Eigen::Vector2d(1.2e-3, 0.8e-3), 0.8, 150.0);
  s.line(Eigen::Vector2d(1.2e-3, 0.8e-3), Eigen::Vector2d(-0.3e-3, 0.1e-3), 4.0, 0.0);
  s.line(Eigen::Vector2d(-0.3e-3, 0.1e-3), Eigen::Vector2d(0.9e-3, 0.9e-3), 1.0, 200.0);
  s.dwell(Eigen::Vector2d(0.9e-3, 0.9e-3), 37, 0.0);
  return s;
}

void expectSameRun(ThermalLayer& a, const std::vector<ThermalStep>& sa, ThermalLayer& b,
                   const std::vector<ThermalStep>& sb, const std::string& what)
{
  ASSERT_EQ(sa.size(), sb.size()) << what;
  for (std::size_t k = 0; k < sa.size(); ++k)
  {
    ASSERT_EQ(sa[k].first_index, sb[k].first_index) << what << " step " << k;
    ASSERT_EQ(sa[k].samples, sb[k].samples) << what << " step " << k;
    ASSERT_EQ(sa[k].peak_k, sb[k].peak_k) << what << " step " << k;
    ASSERT_EQ(sa[k].length_m, sb[k].length_m) << what << " step " << k;
    ASSERT_EQ(sa[k].width_m, sb[k].width_m) << what << " step " << k;
    ASSERT_EQ(sa[k].steady, sb[k].steady) << what << " step " << k;
  }
  const ThermalEnergy ea = a.energy(), eb = b.energy();
  EXPECT_EQ(ea.absorbed_j, eb.absorbed_j) << what;
  EXPECT_EQ(ea.stored_j, eb.stored_j) << what;
  EXPECT_EQ(ea.lost_j, eb.lost_j) << what;
  EXPECT_EQ(ea.left_window_j, eb.left_window_j) << what;
  EXPECT_EQ(ea.truncated_j, eb.truncated_j) << what;
  const ThermalWindow wa = a.window(), wb = b.window();
  EXPECT_EQ(wa.origin_i, wb.origin_i) << what;
  EXPECT_EQ(wa.origin_j, wb.origin_j) << what;
  EXPECT_EQ(0, std::memcmp(wa.rise_k.data(), wb.rise_k.data(), wa.rise_k.size() * sizeof(double))) << what;
  EXPECT_EQ(wa.solid, wb.solid) << what;
  EXPECT_EQ(a.meltedRaster().melted, b.meltedRaster().melted) << what;
  EXPECT_EQ(a.stats().steady_length_mean_m, b.stats().steady_length_mean_m) << what;
  EXPECT_EQ(a.stats().max_width_m, b.stats().max_width_m) << what;
}
}  // namespace

TEST(ThermalLayer, ChunkingIsBitIdentical)
{
  ThermalConfig c;
  c.window_m = 1.2e-3;
  c.step_samples = 3;  // chunk borders fall inside steps
  c.settle_time_s = 0.2e-3;
  const Stream s = mixedJob();
  ThermalLayer ref(c);
  const std::vector<ThermalStep> sref = feed(ref, s, 1000);
  EXPECT_GT(ref.energy().left_window_j, 0.0);  // the window did move and drop heat
  EXPECT_GT(ref.stats().steady_steps, 0u);
  EXPECT_EQ(sref.back().samples, (s.pos.size() - 1) % 3 + 1);  // finish() runs the short last step
  for (std::size_t chunk : {std::size_t(1), std::size_t(7)})
  {
    ThermalLayer other(c);
    const std::vector<ThermalStep> so = feed(other, s, chunk);
    expectSameRun(ref, sref, other, so, "chunk " + std::to_string(chunk));
  }
  std::cout << "[chunks] " << sref.size() << " steps, " << ref.meltedCellCount() << " cells melted, left window "
            << ref.energy().left_window_j << " J, residual " << ref.energy().residual_j() << " J\n";
  EXPECT_LT(std::abs(ref.energy().residual_j()), 1e-10 * ref.energy().absorbed_j);
}

// A repeated (overlapping) chunk changes nothing; a gap is laser-off time at the last position.
TEST(ThermalLayer, OverlapSkippedGapIsLaserOff)
{
  ThermalConfig c;
  c.window_m = 1.2e-3;
  Stream s = mixedJob();
  ThermalLayer ref(c);
  const std::vector<ThermalStep> sref = feed(ref, s, 100);

  ThermalLayer overlap(c);
  std::vector<ThermalStep> so;
  for (std::size_t start = 0; start < s.pos.size(); start += 100)
  {
    overlap.process(chunkOf(s, start, 100));
    so.insert(so.end(), overlap.recentSteps().begin(), overlap.recentSteps().end());
    overlap.process(chunkOf(s, start >= 50 ? start - 50 : 0, 100));  // half of it again
    so.insert(so.end(), overlap.recentSteps().begin(), overlap.recentSteps().end());
  }
  overlap.finish();
  so.insert(so.end(), overlap.recentSteps().begin(), overlap.recentSteps().end());
  expectSameRun(ref, sref, overlap, so, "overlap");

  // Samples 250..299 (on the last track) laser off at the position of 249, sent as a gap.
  Stream filled = s;
  ASSERT_GT(s.pos.size(), 300u);
  ASSERT_GT(s.power[260], 0.0);
  for (std::size_t k = 250; k < 300; ++k)
  {
    filled.pos[k] = filled.pos[249];
    filled.power[k] = 0.0;
  }
  ThermalLayer a(c), b(c);
  const std::vector<ThermalStep> sa = feed(a, filled, 100);
  std::vector<ThermalStep> sb;
  for (std::size_t start = 0; start < s.pos.size(); start += 50)
  {
    if (start == 250)
      continue;
    b.process(chunkOf(filled, start, 50));
    sb.insert(sb.end(), b.recentSteps().begin(), b.recentSteps().end());
  }
  b.finish();
  sb.insert(sb.end(), b.recentSteps().begin(), b.recentSteps().end());
  expectSameRun(a, sa, b, sb, "gap");
}

TEST(ThermalLayer, BadSamplesNameTheIndex)
{
  ThermalConfig c;
  c.window_m = 1.2e-3;
  ThermalLayer layer(c);
  Stream s;
  s.line(Eigen::Vector2d(0, 0), Eigen::Vector2d(0.2e-3, 0), 1.0, 100.0);
  SpotChunk ch = chunkOf(s, 0, 1000);
  ch.first_index = 12340;
  ch.samples[5].actual.x() = NAN;
  ch.samples[5].power_w = 0.0;
  EXPECT_NO_THROW(layer.process(ch));  // laser off: the position is not used
  layer.reset();
  ch.samples[5].power_w = 50.0;
  try
  {
    layer.process(ch);
    FAIL() << "no throw";
  }
  catch (const NumericalError& e)
  {
    const std::string what = e.what();
    EXPECT_NE(what.find("sample 12345"), std::string::npos) << what;
    EXPECT_NE(what.find("non-finite"), std::string::npos) << what;
  }
  layer.reset();
  ch = chunkOf(s, 0, 1000);
  ch.samples[3].power_w = -1.0;
  EXPECT_THROW(layer.process(ch), NumericalError);
  layer.reset();
  ch = chunkOf(s, 0, 10);
  layer.process(ch);
  ch = chunkOf(s, 10, 10);
  ch.period_s = 2e-5;
  EXPECT_THROW(layer.process(ch), InputError);
  ch.period_s = 0.0;
  EXPECT_THROW(layer.process(ch), InputError);
}
