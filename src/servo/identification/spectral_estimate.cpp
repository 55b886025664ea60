/// \file spectral_estimate.cpp
#include "scanhead/servo/identification/spectral_estimate.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "scanhead/common/config_check.hpp"
#include "scanhead/common/errors.hpp"

namespace scanhead
{
namespace
{
constexpr double kPi = 3.14159265358979323846;
using Complex = std::complex<double>;

bool isPowerOfTwo(std::size_t n)
{
  return n != 0 && (n & (n - 1)) == 0;
}

/// In-place iterative radix-2 FFT (n a power of two); inverse without the 1/n scaling.
void fftRadix2(std::vector<Complex>& a, bool inverse)
{
  const std::size_t n = a.size();
  for (std::size_t i = 1, j = 0; i < n; ++i)
  {
    std::size_t bit = n >> 1;
    for (; j & bit; bit >>= 1)
      j ^= bit;
    j ^= bit;
    if (i < j)
      std::swap(a[i], a[j]);
  }
  for (std::size_t len = 2; len <= n; len <<= 1)
  {
    const double angle = (inverse ? 2.0 : -2.0) * kPi / static_cast<double>(len);
    const std::size_t half = len / 2;
    // Twiddles computed directly (not by recurrence) for full accuracy at large n.
    std::vector<Complex> w(half);
    for (std::size_t k = 0; k < half; ++k)
      w[k] = std::polar(1.0, angle * static_cast<double>(k));
    for (std::size_t i = 0; i < n; i += len)
      for (std::size_t k = 0; k < half; ++k)
      {
        const Complex t = w[k] * a[i + k + half];
        a[i + k + half] = a[i + k] - t;
        a[i + k] += t;
      }
  }
}

/// Bluestein: X_k = conj(c_k) Σ_n (x_n conj(c_n)) c_{k−n}, c_m = exp(jπ m²/N), as a convolution.
std::vector<Complex> bluestein(const std::vector<Complex>& x)
{
  const std::size_t n = x.size();
  std::size_t m = 1;
  while (m < 2 * n - 1)
    m <<= 1;
  std::vector<Complex> chirp(n);
  for (std::size_t k = 0; k < n; ++k)
  {
    // k² mod 2N keeps the angle argument small (exact in integers).
    const unsigned long long k2 = (static_cast<unsigned long long>(k) * k) % (2ull * n);
    chirp[k] = std::polar(1.0, kPi * static_cast<double>(k2) / static_cast<double>(n));
  }
  std::vector<Complex> a(m, Complex(0.0, 0.0)), b(m, Complex(0.0, 0.0));
  for (std::size_t k = 0; k < n; ++k)
    a[k] = x[k] * std::conj(chirp[k]);
  b[0] = chirp[0];
  for (std::size_t k = 1; k < n; ++k)
    b[k] = b[m - k] = chirp[k];
  fftRadix2(a, false);
  fftRadix2(b, false);
  for (std::size_t k = 0; k < m; ++k)
    a[k] *= b[k];
  fftRadix2(a, true);
  std::vector<Complex> out(n);
  const double scale = 1.0 / static_cast<double>(m);
  for (std::size_t k = 0; k < n; ++k)
    out[k] = a[k] * scale * std::conj(chirp[k]);
  return out;
}

}  // namespace

void WelchConfig::validate(const std::string& prefix) const
{
  if (segment_length < 8)
    failSetting(prefix + ".segment_length", ">= 8", segment_length);
  if (overlap >= segment_length)
    failSetting(prefix + ".overlap", "< segment_length (" + std::to_string(segment_length) + ")", overlap);
  if (!(sample_period_s > 0.0) || !std::isfinite(sample_period_s))
    failSetting(prefix + ".sample_period_s", "> 0", sample_period_s);
}

std::vector<Complex> discreteFourierTransform(const std::vector<Complex>& x)
{
  if (x.size() <= 1)
    return x;
  if (isPowerOfTwo(x.size()))
  {
    std::vector<Complex> a = x;
    fftRadix2(a, false);
    return a;
  }
  return bluestein(x);
}

FrequencyResponse estimateH1(const std::vector<double>& u, const std::vector<double>& y, const WelchConfig& config)
{
  config.validate("welch");
  if (u.size() != y.size())
    throw InputError("estimateH1: input and output lengths differ (" + std::to_string(u.size()) + " vs " +
                     std::to_string(y.size()) + ")");
  const std::size_t d = config.segment_length;
  if (u.size() < d)
    throw InputError("estimateH1: " + std::to_string(u.size()) + " samples, fewer than one segment (" +
                     std::to_string(d) + ")");
  const std::size_t step = d - config.overlap;
  const std::size_t segments = (u.size() - d) / step + 1;
  const std::size_t bins = d / 2 + 1;

  std::vector<double> w(d, 1.0);
  if (config.window == SpectralWindow::Hann)
    for (std::size_t n = 0; n < d; ++n)
    {
      const double s = std::sin(kPi * static_cast<double>(n) / static_cast<double>(d));
      w[n] = s * s;
    }
  double w2 = 0.0;
  for (double v : w)
    w2 += v * v;
  // T/(D·U) with U = Σw²/D, doubled for the one-sided density except at DC (and Nyquist).
  const double scale = config.sample_period_s / w2;

  std::vector<double> puu(bins, 0.0), pyy(bins, 0.0);
  std::vector<Complex> puy(bins, Complex(0.0, 0.0));
  std::vector<Complex> z(d);
  for (std::size_t p = 0; p < segments; ++p)
  {
    const std::size_t start = p * step;
    // Both real segments in one complex transform: z = u + j y, then separate by symmetry.
    for (std::size_t n = 0; n < d; ++n)
      z[n] = Complex(w[n] * u[start + n], w[n] * y[start + n]);
    const std::vector<Complex> zf = discreteFourierTransform(z);
    for (std::size_t k = 0; k < bins; ++k)
    {
      const Complex a = zf[k];
      const Complex b = std::conj(zf[(d - k) % d]);
      const Complex uk = 0.5 * (a + b);
      const Complex yk = Complex(0.0, -0.5) * (a - b);
      puu[k] += std::norm(uk);
      pyy[k] += std::norm(yk);
      puy[k] += std::conj(uk) * yk;
    }
  }

  FrequencyResponse out;
  out.segments = segments;
  out.frequency_hz.resize(bins);
  out.response.resize(bins);
  out.coherence.resize(bins);
  out.input_psd.resize(bins);
  const double df = 1.0 / (static_cast<double>(d) * config.sample_period_s);
  for (std::size_t k = 0; k < bins; ++k)
  {
    const double one_sided = (k == 0 || 2 * k == d) ? 1.0 : 2.0;
    const double norm = one_sided * scale / static_cast<double>(segments);
    out.frequency_hz[k] = df * static_cast<double>(k);
    out.input_psd[k] = puu[k] * norm;
    out.response[k] = puu[k] > 0.0 ? puy[k] / puu[k] : Complex(0.0, 0.0);
    const double den = puu[k] * pyy[k];
    out.coherence[k] = den > 0.0 ? std::min(1.0, std::norm(puy[k]) / den) : 0.0;
  }
  return out;
}
}  // namespace scanhead
