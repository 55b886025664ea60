#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <random>
#include <vector>

#include "scanhead/common/errors.hpp"
#include "scanhead/servo/identification/prbs.hpp"
#include "scanhead/servo/identification/spectral_estimate.hpp"

using namespace scanhead;
using Complex = std::complex<double>;

namespace
{
constexpr double kPi = 3.14159265358979323846;

/// y[n] = a·y[n−1] + (1 − a)·u[n]: H(e^{jΩ}) = (1 − a)/(1 − a e^{−jΩ}).
std::vector<double> firstOrderIir(const std::vector<double>& u, double a)
{
  std::vector<double> y(u.size());
  double state = 0.0;
  for (std::size_t n = 0; n < u.size(); ++n)
    y[n] = state = a * state + (1.0 - a) * u[n];
  return y;
}

Complex iirResponse(double f_hz, double period_s, double a)
{
  const Complex z1 = std::polar(1.0, -2.0 * kPi * f_hz * period_s);
  return (1.0 - a) / (1.0 - a * z1);
}
}  // namespace

// The DFT (radix-2 and Bluestein) against the direct sum, for lengths 16, 15 and 127:
// round-off only (1e-12 relative to Σ|x|).
TEST(SpectralEstimate, DftMatchesDirectSum)
{
  std::mt19937 rng(7);
  std::normal_distribution<double> g;
  for (std::size_t n : {16u, 15u, 127u})
  {
    std::vector<Complex> x(n);
    double sum = 0.0;
    for (Complex& v : x)
    {
      v = Complex(g(rng), g(rng));
      sum += std::abs(v);
    }
    const std::vector<Complex> fx = discreteFourierTransform(x);
    for (std::size_t k = 0; k < n; ++k)
    {
      Complex direct(0.0, 0.0);
      for (std::size_t m = 0; m < n; ++m)
        direct += x[m] * std::polar(1.0, -2.0 * kPi * double((k * m) % n) / double(n));
      ASSERT_LT(std::abs(fx[k] - direct), 1e-12 * sum) << "n " << n << " k " << k;
    }
  }
}

// Random input through a first-order IIR (pole 0.95), Hann window, D = 1024, 50 % overlap,
// 2^18 samples (511 segments). H1 is asymptotically unbiased; the residual bias is the Hann
// window's smoothing of H over ±2 bins plus the segment-edge transients (impulse response
// ~20 samples vs D = 1024): < 1 % in magnitude and < 0.6° in phase (measured 0.65 % / 0.30°);
// noise-free and linear, so the coherence is 1 but for the same edge effect, ~ 2·20/1024 at
// the lowest bins (measured ≥ 0.9949): asserted > 0.99.
TEST(SpectralEstimate, H1RecoversFirstOrderIir)
{
  const double period_s = 1e-4;
  const double a = 0.95;
  std::mt19937 rng(42);
  std::normal_distribution<double> g;
  std::vector<double> u(1u << 18);
  for (double& v : u)
    v = g(rng);
  const std::vector<double> y = firstOrderIir(u, a);
  WelchConfig config;
  config.segment_length = 1024;
  config.overlap = 512;
  config.window = SpectralWindow::Hann;
  config.sample_period_s = period_s;
  const FrequencyResponse h = estimateH1(u, y, config);
  ASSERT_EQ(h.frequency_hz.size(), 513u);
  EXPECT_EQ(h.segments, 511u);
  EXPECT_NEAR(h.frequency_hz[1], 1.0 / (1024 * period_s), 1e-9);
  double worst_mag = 0.0, worst_phase = 0.0;
  for (std::size_t k = 1; k + 1 < h.response.size(); ++k)
  {
    const Complex truth = iirResponse(h.frequency_hz[k], period_s, a);
    worst_mag = std::max(worst_mag, std::abs(std::abs(h.response[k]) / std::abs(truth) - 1.0));
    worst_phase = std::max(worst_phase, std::abs(std::arg(h.response[k] / truth)) * 180.0 / kPi);
    EXPECT_GT(h.coherence[k], 0.99) << "bin " << k;
  }
  EXPECT_LT(worst_mag, 0.01);
  EXPECT_LT(worst_phase, 0.6);
  // One-sided PSD of unit white noise: 2·T = 2e-4 per Hz, mean over bins within 2 % (511 averages).
  double mean_psd = 0.0;
  for (std::size_t k = 1; k + 1 < h.input_psd.size(); ++k)
    mean_psd += h.input_psd[k];
  mean_psd /= double(h.input_psd.size() - 2);
  EXPECT_NEAR(mean_psd, 2.0 * period_s, 0.02 * 2.0 * period_s);
  std::printf("IIR H1: max |mag err| %.3g, max phase err %.3g deg\n", worst_mag, worst_phase);
}

// Output noise: H1 stays unbiased and the coherence falls to S/(S + N), S = |H|²Φuu, N = Φnn.
// Noise σ = 0.05 on y of the same filter; at low frequency |H| ≈ 1 so γ² ≈ 1/(1 + 0.0025/1) ≈ 0.9975,
// near Nyquist |H|² = (0.05/1.95)² so γ² ≈ 0.21. Each bin within ±0.1 (511 averages: the
// coherence estimate's spread is ~ sqrt(2)·γ(1 − γ²)/sqrt(P) ≤ 0.025, so 4σ), and the mean
// deviation over all bins within ±0.01 (no bias); response within 5σ + 1 % of the truth, with the
// H1 random error σ = sqrt((1 − γ²)/(2·P_eff·γ²)) (Bendat & Piersol), P_eff = 0.8·P for 50 %
// overlapped Hann segments (≈ 6 % where γ² ≈ 0.21).
TEST(SpectralEstimate, CoherenceDropsWithOutputNoise)
{
  const double period_s = 1e-4;
  const double a = 0.95;
  std::mt19937 rng(3);
  std::normal_distribution<double> g;
  std::vector<double> u(1u << 18);
  for (double& v : u)
    v = g(rng);
  std::vector<double> y = firstOrderIir(u, a);
  for (double& v : y)
    v += 0.05 * g(rng);
  WelchConfig config;
  config.segment_length = 1024;
  config.overlap = 512;
  config.sample_period_s = period_s;
  const FrequencyResponse h = estimateH1(u, y, config);
  double mean_dev = 0.0;
  for (std::size_t k = 1; k + 1 < h.response.size(); ++k)
  {
    const Complex truth = iirResponse(h.frequency_hz[k], period_s, a);
    const double signal = std::norm(truth) * 1.0;  // white unit input: Φuu flat, same scale as Φnn
    const double expected = signal / (signal + 0.05 * 0.05);
    EXPECT_NEAR(h.coherence[k], expected, 0.1) << "bin " << k;
    mean_dev += h.coherence[k] - expected;
    const double sigma = std::sqrt((1.0 - expected) / (2.0 * 0.8 * double(h.segments) * expected));
    EXPECT_LT(std::abs(h.response[k] / truth - 1.0), 5.0 * sigma + 0.01) << "bin " << k;
  }
  mean_dev /= double(h.response.size() - 2);
  EXPECT_NEAR(mean_dev, 0.0, 0.01);
  std::printf("noisy H1: mean coherence deviation %.3g\n", mean_dev);
}

// Periodic PRBS, rectangular window, segment = one period: after the transient (dropped), the
// DFT lines of a steady periodic response give H exactly (round-off only: 1e-9).
TEST(SpectralEstimate, SynchronousPrbsIsExact)
{
  PrbsConfig pc;
  pc.order = 9;
  Prbs prbs(pc);
  const std::size_t n = prbs.periodSamples();
  const std::vector<double> u = prbs.take(6 * n);
  std::vector<double> y = firstOrderIir(u, 0.9);
  // Drop the first period (transient 0.9^511 ≈ 4e-24).
  const std::vector<double> us(u.begin() + n, u.end()), ys(y.begin() + n, y.end());
  WelchConfig config;
  config.segment_length = n;
  config.overlap = 0;
  config.window = SpectralWindow::Rectangular;
  config.sample_period_s = 1.0;
  const FrequencyResponse h = estimateH1(us, ys, config);
  EXPECT_EQ(h.segments, 5u);
  for (std::size_t k = 1; k < h.response.size(); ++k)
    ASSERT_LT(std::abs(h.response[k] / iirResponse(h.frequency_hz[k], 1.0, 0.9) - 1.0), 1e-9) << k;
}

TEST(SpectralEstimate, RejectsBadInput)
{
  WelchConfig config;
  config.segment_length = 64;
  config.overlap = 64;
  std::vector<double> u(100, 1.0);
  EXPECT_THROW(estimateH1(u, u, config), ConfigError);
  config.overlap = 0;
  EXPECT_THROW(estimateH1(u, std::vector<double>(99), config), InputError);
  EXPECT_THROW(estimateH1(std::vector<double>(10), std::vector<double>(10), config), InputError);
}
