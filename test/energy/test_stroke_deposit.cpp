/// \file test_stroke_deposit.cpp
/// \brief energy.method exact: the closed form of the swept spot, stroke merging, against quadrature; exact and
/// trapezoid (test_trapezoid_deposit.cpp for its nodes) against the line source and the sampled method at 4× finer
/// sub-steps (issue 13's accuracy targets), their energy, chunking and two threads.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "../src/energy/gauss_legendre.hpp"  // private to src/energy: the bracket's quadrature checked here
#include "../src/energy/lane_math.hpp"       // private to src/energy: its lane exp and erf checked here
#include "fixtures/chain_fixture.hpp"
#include "fixtures/spot_stream_fixture.hpp"
#include "scanhead/common/errors.hpp"
#include "scanhead/energy/energy_accumulator.hpp"
#include "scanhead/energy/segment_integral.hpp"
#include "scanhead/energy/stroke_deposit.hpp"

using scanhead::ConfigError;
using scanhead::EnergyAccumulator;
using scanhead::EnergyConfig;
using scanhead::SegmentIntegral;
using scanhead::SpotChunk;
using scanhead::SpotFootprint;
using scanhead::SpotSample;

namespace
{
constexpr double kTs = scanhead::test_support::kStreamPeriod_s;  // 100 kHz
using Stream = scanhead::test_support::SpotStream;

EnergyConfig withMethod(const std::string& method)
{
  EnergyConfig cfg;
  cfg.method = method;
  if (method == "sampled")
    cfg.max_substep_radii /= 4.0;  // the reference: 4× finer sub-steps than the default
  return cfg;
}

/// \brief Feeds \p s (with beam direction \p direction) in chunks of \p chunk samples, then finish().
void feed(EnergyAccumulator& acc, const Stream& s, std::size_t chunk,
          const Eigen::Vector3d& direction = Eigen::Vector3d(0, 0, -1))
{
  for (std::size_t start = 0; start < s.pos.size(); start += chunk)
  {
    SpotChunk c = s.chunk(start, chunk);
    for (SpotSample& sample : c.samples)
      sample.direction = direction;
    acc.process(c);
  }
  acc.finish();
}

/// \brief max |a − b| / max |b| over two maps of the same size.
double maxDiffOfPeak(const std::vector<float>& a, const std::vector<float>& b)
{
  EXPECT_EQ(a.size(), b.size());
  double diff = 0.0, peak = 0.0;
  for (std::size_t i = 0; i < std::min(a.size(), b.size()); ++i)
  {
    diff = std::max(diff, std::abs(double(a[i]) - double(b[i])));
    peak = std::max(peak, std::abs(double(b[i])));
  }
  return diff / peak;
}

/// \brief A path with straight strokes, a corner, a speed ramp, a power step and a dwell.
Stream mixedPath()
{
  Stream s;
  s.line(Eigen::Vector2d(0.3e-3, 0.3e-3), Eigen::Vector2d(1.2e-3, 0.3e-3), 1.0, 200.0);
  Eigen::Vector2d x = s.pos.back();
  for (int k = 1; k <= 80; ++k)  // accelerating diagonal, then a power step
  {
    x += (0.5 + 0.02 * k) * kTs * Eigen::Vector2d(0.6, 0.8);
    s.add(x, k < 50 ? 200.0 : 120.0);
  }
  s.dwell(x, 20, 80.0);
  s.line(x, Eigen::Vector2d(0.4e-3, 1.1e-3), 2.0, 150.0);
  return s;
}
}  // namespace

// The closed form against a direct quadrature of ∫0^1 exp(−(r − τD)ᵀQ(r − τD)) dτ (composite Simpson, 20,000
// intervals: error ~1e-15), circular and oblique, along and across, and the stationary limit.
TEST(SegmentIntegral, MatchesQuadrature)
{
  SpotFootprint circular;
  circular.qxx = circular.qyy = 2.0 / (35e-6 * 35e-6);
  SpotFootprint oblique;  // a beam 20° off normal in the direction (0.6, 0.8)
  {
    const double w = 35e-6, a = 2.0 / (w * w), s = std::sin(20.0 * M_PI / 180.0);
    const double dx = 0.6 * s, dy = 0.8 * s;
    oblique.qxx = a * (1 - dx * dx);
    oblique.qxy = -a * dx * dy;
    oblique.qyy = a * (1 - dy * dy);
  }
  for (const SpotFootprint& fp : {circular, oblique})
    for (const Eigen::Vector2d& d : {Eigen::Vector2d(10e-6, 0), Eigen::Vector2d(-30e-6, 45e-6),
                                     Eigen::Vector2d(0, 1e-6), Eigen::Vector2d(1e-15, 0)})
    {
      const SegmentIntegral si(fp, d);
      const double det = fp.qxx * fp.qyy - fp.qxy * fp.qxy;
      for (const Eigen::Vector2d& r : {Eigen::Vector2d(0, 0), Eigen::Vector2d(12e-6, -7e-6),
                                       Eigen::Vector2d(-40e-6, 20e-6), Eigen::Vector2d(60e-6, 55e-6)})
      {
        const int n = 20000;
        double sum = 0.0;
        for (int k = 0; k <= n; ++k)
        {
          const Eigen::Vector2d x = r - (double(k) / n) * d;
          const double f = std::exp(-(fp.qxx * x.x() * x.x() + 2 * fp.qxy * x.x() * x.y() + fp.qyy * x.y() * x.y()));
          sum += f * (k == 0 || k == n ? 1 : (k % 2 == 1 ? 4 : 2));
        }
        const double reference = std::sqrt(det) / M_PI * sum / (3.0 * n);  // E(p) per joule
        const double value = si.density(r, 1.0);
        const double peak = std::sqrt(det) / M_PI;
        EXPECT_NEAR(value, reference, 1e-9 * peak) << "d = " << d.transpose() << ", r = " << r.transpose();
      }
    }
}

// The lane functions of the row kernels against the standard library: e^{−x} within 4e-7 relative over the range
// the kernels use, erf within the 4e-6 absolute that stroke_deposit.hpp states.
TEST(StrokeDeposit, LaneMathMatchesStd)
{
  using scanhead::energy_detail::F8;
  double worst_exp = 0.0, worst_erf = 0.0;
  for (int i = 0; i < 20000; ++i)
  {
    F8 x;
    for (int l = 0; l < 8; ++l)
      x[l] = static_cast<float>((i * 8 + l) * (87.0 / 160000.0));
    const F8 e = scanhead::energy_detail::expNeg(x);
    for (int l = 0; l < 8; ++l)
    {
      const double reference = std::exp(-static_cast<double>(x[l]));
      worst_exp = std::max(worst_exp, std::abs(e[l] - reference) / reference);
    }
    F8 y;
    for (int l = 0; l < 8; ++l)
      y[l] = static_cast<float>(-8.0 + (i * 8 + l) * (16.0 / 160000.0));
    const F8 f = scanhead::energy_detail::erfLanes(y);
    for (int l = 0; l < 8; ++l)
      worst_erf = std::max(worst_erf, std::abs(f[l] - std::erf(static_cast<double>(y[l]))));
  }
  std::cout << "[lanes] exp rel err " << worst_exp << ", erf abs err " << worst_erf << "\n";
  EXPECT_LT(worst_exp, 4e-7);
  EXPECT_LT(worst_erf, 4e-6);
}

// The Gauss–Legendre rules integrate polynomials of degree 2n − 1 exactly, and the rule a stroke's bracket uses
// (bracketRuleNodes) equals erf(u) − erf(u − √A) within 1e-6 for every √A ≤ 6 and u across the capsule.
TEST(StrokeDeposit, BracketQuadratureMatchesErf)
{
  using scanhead::energy_detail::gaussLegendreRule;
  for (int n = 1; n <= scanhead::energy_detail::GaussLegendreRule::kMaxNodes; ++n)
  {
    const auto& rule = gaussLegendreRule(n);
    for (int degree = 0; degree <= 2 * n - 1; ++degree)
    {
      double sum = 0.0;
      for (int i = 0; i < n; ++i)
        sum += rule.weight[i] * std::pow(rule.node[i], degree);
      EXPECT_NEAR(sum, 1.0 / (degree + 1), 1e-14) << n << " nodes, degree " << degree;
    }
  }
  double worst = 0.0;
  for (double sqrt_a = 0.05; sqrt_a <= 6.0 + 1e-9; sqrt_a += 0.05)
  {
    const auto& rule = gaussLegendreRule(scanhead::energy_detail::bracketRuleNodes(sqrt_a));
    for (double u = -4.0; u <= sqrt_a + 4.0; u += 0.01)
    {
      double sum = 0.0;
      for (int i = 0; i < rule.n; ++i)
        sum += rule.weight[i] * std::exp(-(u - sqrt_a * rule.node[i]) * (u - sqrt_a * rule.node[i]));
      const double quadrature = 2.0 / std::sqrt(M_PI) * sqrt_a * sum;
      worst = std::max(worst, std::abs(quadrature - (std::erf(u) - std::erf(u - sqrt_a))));
    }
  }
  std::cout << "[bracket] worst |quadrature − erf difference| = " << worst << "\n";
  EXPECT_LT(worst, 1e-6);
}

// The row-by-row evaluation (a dwell; strokes of √A ≤ 6 by Gauss–Legendre on their rectangle, 4 to 14 nodes; longer
// ones by erf; oblique and circular) equals the closed form at every pixel centre, within the truncation's
// renormalisation and float storage.
TEST(StrokeDeposit, RowsEqualTheClosedForm)
{
  double worst_of_all = 0.0;
  EnergyConfig cfg;
  const double p = cfg.pixel_m;
  SpotFootprint circular;
  circular.qxx = circular.qyy = 2.0 / (35e-6 * 35e-6);
  circular.radius_m = circular.major_radius_m = 35e-6;
  SpotFootprint oblique = scanhead::spotFootprint(cfg, Eigen::Vector3d(0.3, -0.25, -1.0).normalized());
  for (const SpotFootprint& fp : {circular, oblique})
    for (const Eigen::Vector2d& step :
         {Eigen::Vector2d(0, 0), Eigen::Vector2d(3e-6, 4e-6), Eigen::Vector2d(-7e-6, 2e-6), Eigen::Vector2d(0, 11e-6),
          Eigen::Vector2d(13e-6, -13e-6)})
      for (std::uint64_t n : {1u, 3u, 8u, 40u})
      {
        scanhead::Stroke stroke;
        stroke.start = Eigen::Vector2d(0.6e-3 + 0.3 * p, 0.6e-3 - 0.2 * p);
        stroke.step = step;
        stroke.samples = n;
        stroke.power_w = 100.0;
        stroke.period_s = kTs;
        stroke.footprint = fp;
        scanhead::TiledEnergyMap map(Eigen::Vector2d(-0.2e-3, -0.2e-3), Eigen::Vector2d(1.3e-3, 1.3e-3), p, 1u << 24);
        scanhead::StrokeDeposit deposit(cfg);
        scanhead::StrokeWeights weights;
        double outside = 0.0;
        deposit.weigh(map, stroke, weights);
        deposit.apply(map, weights, outside);
        EXPECT_EQ(outside, 0.0);
        EXPECT_NEAR(map.totalEnergy(), stroke.energy(), 1e-6 * stroke.energy());
        const SegmentIntegral si(fp, stroke.displacement());
        double worst = 0.0, peak = 0.0;
        for (std::int64_t j = 0; j < map.height(); ++j)
          for (std::int64_t i = 0; i < map.width(); ++i)
          {
            const Eigen::Vector2d r =
                map.origin() + (Eigen::Vector2d(double(i), double(j)) + Eigen::Vector2d(0.5, 0.5)) * p - stroke.start;
            const double reference = si.density(r, stroke.energy());
            peak = std::max(peak, reference);
            worst = std::max(worst, std::abs(map.at(i, j) - reference));
          }
        // Expected: the tail beyond 2.5 w_major renormalised (≤ 4e-6) + float storage (6e-8) + the pixel sum
        // against the integral (the Poisson sum: ~e^{-π²w²/(2p²)}, nil at w = 7 pixels).
        EXPECT_LT(worst, 1e-5 * peak) << "step " << step.transpose() << ", n " << n << ", oblique " << fp.qxy;
        worst_of_all = std::max(worst_of_all, worst / peak);
      }
  std::cout << "[closed form] worst |deposit − closed form| = " << worst_of_all << " of the peak\n";
}

// energy.method and energy.stroke_tolerance_m are checked and named.
TEST(StrokeDeposit, SettingsAreValidated)
{
  EnergyConfig c;
  c.method = "fast";
  try
  {
    c.validate();
    FAIL() << "no throw";
  }
  catch (const ConfigError& e)
  {
    EXPECT_EQ(std::string(e.what()), "energy.method must be trapezoid, exact or sampled (got 'fast')");
  }
  c = EnergyConfig();
  c.stroke_tolerance_m = 1e-3;
  try
  {
    c.validate();
    FAIL() << "no throw";
  }
  catch (const ConfigError& e)
  {
    EXPECT_EQ(std::string(e.what()), "energy.stroke_tolerance_m must be in [0, 1e-6] m (got 0.001)");
  }
}

// Issue 13: across a long straight track at constant speed the map equals the line source
// (P/v)·√(2/π)/w·exp(−2d²/w²) within 0.5 % (circular footprint, away from the ends), and the track is merged
// into strokes (2,048 pixels long at most).
TEST(StrokeDeposit, StraightTrackIsTheLineSource)
{
  for (const char* method : {"exact", "trapezoid"})
  {
    EnergyConfig cfg = withMethod(method);
    cfg.oblique_incidence = false;
    cfg.pixel_m = 2.5e-6;  // w = 14 pixels: the profile is sampled exactly at d = 0, w/2, w
    const double w = 0.5 * cfg.spot_diameter_m, p = cfg.pixel_m;
    const double v = 1.5, power = 200.0;
    EnergyAccumulator acc(cfg, Eigen::Vector2d(0, 0), Eigen::Vector2d(6e-3, 0.4e-3));
    const double y = 80.5 * p;
    Stream s;
    s.line(Eigen::Vector2d(0.3e-3, y), Eigen::Vector2d(5.7e-3, y), v, power);
    feed(acc, s, 1000);
    const scanhead::EnergyMap map = acc.map().toDense();
    double worst = 0.0;
    for (int col = static_cast<int>(0.3e-3 / p + 8 * w / p); col < static_cast<int>(5.7e-3 / p - 8 * w / p); col += 7)
      for (int dpx : {0, 7, 14, -7, -14, 21})
      {
        const double d = dpx * p;
        const double ref = power / v * std::sqrt(2.0 / M_PI) / w * std::exp(-2.0 * d * d / (w * w));
        worst = std::max(worst, std::abs(map.at(col, 80 + dpx) - ref) / ref);
      }
    std::cout << "[line source] " << method << ": worst rel err " << worst << "; " << acc.samplesDeposited()
              << " samples in " << acc.strokesDeposited() << " strokes (windows), "
              << double(acc.pixelsDrawn()) / acc.samplesDeposited() << " pixels per sample\n";
    // Issue: 0.5 %. Expected: truncation at 2.5 w (the renormalised tail: 4e-6) + float storage.
    EXPECT_LT(worst, 1e-4) << method;
    EXPECT_NEAR(map.totalEnergy(), s.commandedEnergy(), 1e-6 * s.commandedEnergy());
    EXPECT_EQ(acc.samplesDeposited(), s.pos.size());
    if (std::string(method) == "exact")
    {
      // 5.4 mm = 2,160 pixels: two strokes of at most 2,048 pixels, and the final dwell.
      EXPECT_LE(acc.strokesDeposited(), 3u);
      EXPECT_GE(acc.strokesDeposited(), 2u);
    }
  }
}

// No ripple at any speed: a track at 6 m/s (60 µm = 1.7 w per sample, where the sampled method without sub-steps
// ripples by 37 %: test_energy_map.cpp) with its samples jittered by ±1.5 merge tolerances across, so that nothing
// merges.
TEST(StrokeDeposit, NoRippleAtHighSpeed)
{
  for (const char* method : {"exact", "trapezoid"})
  {
    EnergyConfig cfg = withMethod(method);
    const double w = 0.5 * cfg.spot_diameter_m, p = cfg.pixel_m;
    EnergyAccumulator acc(cfg, Eigen::Vector2d(0, 0), Eigen::Vector2d(2e-3, 0.4e-3));
    const double y = 40.5 * p;
    Stream s;
    s.line(Eigen::Vector2d(0.3e-3, y), Eigen::Vector2d(1.7e-3, y), 6.0, 200.0);
    for (std::size_t k = 0; k < s.pos.size(); ++k)
      s.pos[k].y() += (k % 2 == 0 ? 1.0 : -1.0) * 1.5 * cfg.stroke_tolerance_m;
    feed(acc, s, 1000);
    if (std::string(method) == "exact")
    {
      EXPECT_EQ(acc.strokesDeposited(), acc.samplesDeposited());
    }
    const int c0 = static_cast<int>((0.3e-3 + 4 * w) / p), c1 = static_cast<int>((1.7e-3 - 4 * w) / p);
    float lo = acc.map().at(c0, 40), hi = lo;
    for (int c = c0; c <= c1; ++c)
    {
      lo = std::min(lo, acc.map().at(c, 40));
      hi = std::max(hi, acc.map().at(c, 40));
    }
    std::cout << "[6 m/s] " << method << ": centre-line ripple " << (hi - lo) / hi << "\n";
    EXPECT_LT((hi - lo) / hi, 1e-4) << method;  // as the sampled method's brief; expected: float storage, ~1e-6
  }
}

// Merging follows the stated rule: a path off the line by more than the tolerance is not merged, within it is.
TEST(StrokeDeposit, MergesOnlyWithinTheTolerance)
{
  Stream straight, wavy;
  straight.line(Eigen::Vector2d(0.2e-3, 0.5e-3), Eigen::Vector2d(0.8e-3, 0.5e-3), 1.0, 100.0);
  wavy = straight;
  for (std::size_t k = 0; k < wavy.pos.size(); ++k)
    // ±1.2 tol: no line lies within tol of three samples in a row
    wavy.pos[k].y() += (k % 2 == 0 ? 1.0 : -1.0) * 1.2 * EnergyConfig().stroke_tolerance_m;
  for (const Stream* s : {&straight, &wavy})
  {
    EnergyAccumulator acc(withMethod("exact"), Eigen::Vector2d(0, 0), Eigen::Vector2d(1e-3, 1e-3));
    feed(acc, *s, 7);
    std::cout << "[merge] " << acc.samplesDeposited() << " samples, " << acc.strokesDeposited() << " strokes\n";
    if (s == &straight)
      EXPECT_EQ(acc.strokesDeposited(), 2u);  // the line and the final dwell
    else
      EXPECT_GT(acc.strokesDeposited(), s->pos.size() / 3);
  }
}

// Energy conserved on a mixed path; the part off the map accounted.
TEST(StrokeDeposit, EnergyConservedAndOffMapAccounted)
{
  const Stream s = mixedPath();
  for (const char* method : {"exact", "trapezoid"})
  {
    EnergyAccumulator inside(withMethod(method), Eigen::Vector2d(0, 0), Eigen::Vector2d(2.5e-3, 2.5e-3));
    feed(inside, s, 1000);
    EXPECT_EQ(inside.energyOutsideMap(), 0.0);
    EXPECT_NEAR(inside.map().totalEnergy(), s.commandedEnergy(), 1e-6 * s.commandedEnergy());
    EnergyAccumulator cut(withMethod(method), Eigen::Vector2d(0, 0), Eigen::Vector2d(0.8e-3, 1.5e-3));
    feed(cut, s, 1000);
    EXPECT_GT(cut.energyOutsideMap(), 0.1 * s.commandedEnergy());
    EXPECT_NEAR(cut.map().totalEnergy() + cut.energyOutsideMap(), s.commandedEnergy(), 1e-6 * s.commandedEnergy());
  }
}

// exact against sampled at 4× finer sub-steps: circular, oblique and defocused footprints, within 0.2 % of the peak.
TEST(StrokeDeposit, MatchesFineSampling)
{
  const Stream s = mixedPath();
  struct Case
  {
    const char* name;
    Eigen::Vector3d direction;
    std::string defocus_mode;
  };
  const Eigen::Vector3d tilted = Eigen::Vector3d(0.25, -0.2, -1.0).normalized();  // 18° of incidence
  for (const Case& c : {Case{"normal", Eigen::Vector3d(0, 0, -1), "none"}, Case{"oblique", tilted, "none"},
                        Case{"defocused", tilted, "fixed"}})
  {
    std::vector<std::vector<float>> maps;
    for (const char* method : {"sampled", "exact", "trapezoid"})
    {
      EnergyConfig cfg = withMethod(method);
      cfg.defocus_mode = c.defocus_mode;
      cfg.defocus_m = 5e-3;  // w × 1.8
      EnergyAccumulator acc(cfg, Eigen::Vector2d(0, 0), Eigen::Vector2d(2.5e-3, 2.5e-3));
      feed(acc, s, 1000, c.direction);
      EXPECT_EQ(acc.energyOutsideMap(), 0.0);
      maps.push_back(acc.map().toDense().data());
    }
    for (std::size_t m = 1; m < maps.size(); ++m)
    {
      const double diff = maxDiffOfPeak(maps[m], maps[0]);
      std::cout << "[fine sampling] " << c.name << ": max |" << (m == 1 ? "exact" : "trapezoid")
                << " − sampled/4| = " << diff << " of the peak\n";
      EXPECT_LT(diff, 2e-3) << c.name;  // issue 13
    }
  }
}

// Chunks of 1, 7 and 1000 samples give bit-identical maps and outside energies (the pending stroke carried).
TEST(StrokeDeposit, ChunkInvariance)
{
  std::mt19937 rng(4321);  // fixed seed
  Stream s = mixedPath();
  Eigen::Vector2d x(0.5e-3, 0.5e-3), v(1.5, 0.3);
  for (int k = 0; k < 2000; ++k)
  {
    if (k % 200 == 0)
      v = Eigen::Vector2d(double(rng() % 4000) / 1000.0 - 2.0, double(rng() % 4000) / 1000.0 - 2.0);
    x += v * kTs;
    s.add(x, (k / 150) % 3 == 0 ? 0.0 : 100.0 + 10.0 * ((k / 300) % 2));
  }
  for (const char* method : {"exact", "trapezoid"})
  {
    std::vector<std::vector<float>> maps;
    std::vector<double> outsides;
    std::vector<std::uint64_t> strokes;
    for (std::size_t chunk : {1u, 7u, 1000u})
    {
      EnergyAccumulator acc(withMethod(method), Eigen::Vector2d(0.2e-3, 0.2e-3), Eigen::Vector2d(1.0e-3, 1.0e-3));
      feed(acc, s, chunk);
      maps.push_back(acc.map().toDense().data());
      outsides.push_back(acc.energyOutsideMap());
      strokes.push_back(acc.strokesDeposited());
    }
    EXPECT_GT(outsides[0], 0.0);
    EXPECT_LT(strokes[0], s.pos.size() / 4);  // exact: the constant-velocity stretches were merged; trapezoid: windows
    for (std::size_t i = 1; i < maps.size(); ++i)
    {
      EXPECT_TRUE(maps[i] == maps[0]) << method << ", chunking " << i;
      EXPECT_EQ(outsides[i], outsides[0]);
      EXPECT_EQ(strokes[i], strokes[0]);
    }
  }
}

// The two-thread form (stage, weighStaged on two threads, applyStaged: what EnergyStage does with stream.threads = 2)
// gives the map of process(), bit for bit, at any chunking, also when a chunk stages more than kMaxStagedStrokes
// strokes or windows (exact: one stroke a sample, the power alternates; trapezoid: 100 000 samples, ≤ 64 nodes a
// window) and stage() draws them itself.
TEST(StrokeDeposit, StagedOnTwoThreadsEqualsProcess)
{
  for (const char* method : {"exact", "trapezoid"})
  {
    const bool exact = std::string(method) == "exact";
    const int samples = exact ? 4000 : 100000;
    Stream s = mixedPath();
    Eigen::Vector2d x(0.5e-3, 0.5e-3), v(1.5, 0.3);
    for (int k = 0; k < samples; ++k)
    {
      if (k % 400 == 0)
        v = Eigen::Vector2d(std::cos(0.7 * k), std::sin(0.7 * k)) * (1.0 + (k / 400) % 3);
      if ((x + v * kTs - Eigen::Vector2d(0.6e-3, 0.6e-3)).norm() > 0.5e-3)
        v = -v;  // stay on and around the map
      x += v * kTs;
      const double power = k < 2500 ? ((k / 150) % 3 == 0 ? 0.0 : 100.0) : 100.0 + 10.0 * (k % 2);
      s.add(x, power);
    }
    const EnergyConfig cfg = withMethod(method);
    const Eigen::Vector2d lo(0.2e-3, 0.2e-3), hi(1.0e-3, 1.0e-3);
    for (const std::size_t chunk : {std::size_t{7}, std::size_t{1000}, static_cast<std::size_t>(samples)})
    {
      EnergyAccumulator one(cfg, lo, hi), two(cfg, lo, hi);
      feed(one, s, chunk);
      for (std::size_t start = 0; start < s.pos.size(); start += chunk)
      {
        two.stage(s.chunk(start, chunk));
        std::thread helper([&two] { two.weighStaged(); });
        two.weighStaged();
        helper.join();
        two.applyStaged();
      }
      two.finish();
      EXPECT_GT(one.strokesDeposited(), EnergyAccumulator::kMaxStagedStrokes) << method;
      EXPECT_TRUE(one.map().toDense().data() == two.map().toDense().data()) << method << ", chunk " << chunk;
      EXPECT_EQ(one.energyOutsideMap(), two.energyOutsideMap());
      EXPECT_EQ(one.strokesDeposited(), two.strokesDeposited());
      EXPECT_EQ(one.pixelsDrawn(), two.pixelsDrawn());
    }
  }
}

// Issue 13: on the chain's own spot streams (servo, optics, oblique footprint) exact and trapezoid are within 0.2 % of
// the peak of sampled at 4× finer sub-steps: the corner job, a 5 mm hatch and one THESIS square.
TEST(StrokeDeposit, ChainJobsMatchFineSampling)
{
  struct Job
  {
    std::string spec;
    std::vector<std::string> overrides;
  };
  for (const Job& job : {Job{"corner", {}}, Job{"hatch:size=0.005,spacing=0.0001", {}},
                         Job{"squares:rows=1,columns=1", {"recipe.preset=thesis1"}}})
  {
    std::vector<std::string> sampled = job.overrides;
    sampled.push_back("energy.method=sampled");
    sampled.push_back("energy.max_substep_radii=0.125");
    const scanhead::test_support::ChainRun b = scanhead::test_support::runJob(job.spec, sampled);
    for (const char* method : {"exact", "trapezoid"})
    {
      std::vector<std::string> overrides = job.overrides;
      overrides.push_back(std::string("energy.method=") + method);
      const scanhead::test_support::ChainRun a = scanhead::test_support::runJob(job.spec, overrides);
      const double diff = maxDiffOfPeak(a.map, b.map);
      std::cout << "[chain] " << job.spec << ": max |" << method << " − sampled/4| = " << diff << " of the peak\n";
      EXPECT_LT(diff, 2e-3) << job.spec << ", " << method;
    }
  }
}

// Against the converged path integral (sampled at 16× finer sub-steps, whose own error is ~4e-5: its midpoint rule
// converges as the square of the sub-step, and 4× finer is 6e-4 off) both closed-form and trapezoid maps are within
// 3e-4 of the peak on the corner job and a 5 mm hatch (measured: exact 2.2e-4 and 1.8e-4, trapezoid 1.1e-4 and 7.5e-5).
TEST(StrokeDeposit, ChainJobsMatchConvergedSampling)
{
  for (const char* spec : {"corner", "hatch:size=0.005,spacing=0.0001"})
  {
    const scanhead::test_support::ChainRun reference =
        scanhead::test_support::runJob(spec, {"energy.method=sampled", "energy.max_substep_radii=0.03125"});
    for (const char* method : {"exact", "trapezoid"})
    {
      const scanhead::test_support::ChainRun a =
          scanhead::test_support::runJob(spec, {std::string("energy.method=") + method});
      const double diff = maxDiffOfPeak(a.map, reference.map);
      std::cout << "[converged] " << spec << ": max |" << method << " − sampled/16| = " << diff << " of the peak\n";
      EXPECT_LT(diff, 3e-4) << spec << ", " << method;
    }
  }
}
