/// \file spectral_estimate.hpp
/// \brief Non-parametric frequency response: H1 estimator with Welch averaging (THESIS app. A.2, SPEC §3).
#pragma once

#include <complex>
#include <cstddef>
#include <string>
#include <vector>

namespace scanhead
{
/// \brief Weighting window w(n) of each Welch segment.
enum class SpectralWindow
{
  Rectangular,  ///< w = 1: exact for a periodic excitation whose period divides the segment
  Hann          ///< periodic Hann, w(n) = sin²(π n / D): for random or non-synchronous signals
};

/// \brief Welch segmentation: P segments of D samples, each starting S = D − overlap after the last.
struct WelchConfig
{
  std::size_t segment_length = 4096;  ///< D [samples], any length ≥ 8 (FFT by Bluestein if not 2^k)
  std::size_t overlap = 2048;         ///< D − S [samples], < segment_length
  SpectralWindow window = SpectralWindow::Hann;
  double sample_period_s = 1.0e-5;  ///< T_ech [s]

  /// \throws ConfigError "<prefix>.<field> ..." (segment_length ≥ 8, overlap < segment_length,
  /// sample_period_s > 0)
  void validate(const std::string& prefix) const;
};

/// \brief One-sided frequency response estimate on the DFT bins k = 0 … D/2.
struct FrequencyResponse
{
  std::vector<double> frequency_hz;            ///< f_k = k / (D·T) [Hz]
  std::vector<std::complex<double>> response;  ///< H1(f_k) = Φuy/Φuu (0 where Φuu = 0)
  std::vector<double> coherence;               ///< γ²(f_k) = |Φuy|² / (Φuu Φyy) in [0, 1]
  std::vector<double> input_psd;               ///< Φuu(f_k) [unit(u)²/Hz], one-sided
  std::size_t segments = 0;                    ///< P, number of averaged segments
};

/// \brief H1 estimate of the response from \p u to \p y (THESIS app. A.2):
/// \f[ \hat G(f) = \frac{\Phi_{uy}(f)}{\Phi_{uu}(f)},\qquad
///     \Phi_{uy}(f) = \frac{1}{P}\sum_{p=0}^{P-1}\frac{T}{D\,U}\,U_p^*(f)\,Y_p(f),\qquad
///     U = \frac{1}{D}\sum_n w(n)^2, \f]
/// \f$U_p, Y_p\f$ the DFTs of the windowed p-th segments \f$w(n)u(pS + n)\f$,
/// \f$w(n)y(pS + n)\f$; coherence \f$\gamma^2 = |\Phi_{uy}|^2/(\Phi_{uu}\Phi_{yy})\f$.
/// Unbiased against noise on \p y (not on \p u). No detrending: remove drifts before.
/// \throws ConfigError on an invalid config; InputError if the lengths differ or are shorter than D
FrequencyResponse estimateH1(const std::vector<double>& u, const std::vector<double>& y, const WelchConfig& config);

/// \brief Discrete Fourier transform of any length (radix-2, or Bluestein's chirp-z through
/// radix-2 for other lengths): \f$X_k = \sum_n x_n e^{-2\pi j k n / N}\f$.
std::vector<std::complex<double>> discreteFourierTransform(const std::vector<std::complex<double>>& x);
}  // namespace scanhead
