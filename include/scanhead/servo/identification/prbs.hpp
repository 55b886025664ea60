/// \file prbs.hpp
/// \brief Maximum-length pseudo-random binary sequence (PRBS, French SBPA), the identification
/// excitation of THESIS app. A.1 (SPEC §3).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace scanhead
{
/// \brief Parameters of a PRBS excitation.
struct PrbsConfig
{
  int order = 16;          ///< n, shift-register length; period 2^n − 1 bits (2 ≤ n ≤ 24)
  int clock_divider = 1;   ///< samples per bit (the PRBS clock is the sample rate / this)
  double amplitude = 1.0;  ///< output levels ±amplitude (unit of the excited quantity, e.g. V)

  /// \throws ConfigError "<prefix>.<field> must be ..." (order in [2, 24], clock_divider ≥ 1,
  /// amplitude > 0 and finite)
  void validate(const std::string& prefix) const;
};

/// \brief Fibonacci linear-feedback shift register with a primitive feedback polynomial
/// (taps of Xilinx XAPP052, Table 3), mapped 0 → −a, 1 → +a (THESIS app. A.1):
/// \f[ x_{k+1} = A\,x_k \ (\mathrm{mod}\ 2),\qquad P(\lambda) = 1 \oplus \alpha_1\lambda \oplus \dots
///     \oplus \alpha_n \lambda^n \ \text{primitive} \Rightarrow \text{period } N = 2^n - 1, \f]
/// with \f$2^{n-1}\f$ ones and \f$2^{n-1} - 1\f$ zeros per period, and the periodic
/// autocorrelation \f$R(0) = a^2\f$, \f$R(k \ne 0 \bmod N) = -a^2/N\f$ (per bit).
/// Each bit is held clock_divider samples. Deterministic: the register starts all ones.
class Prbs
{
public:
  /// \throws ConfigError on an invalid config (names "prbs.<field>")
  explicit Prbs(const PrbsConfig& config);
  /// \brief Back to the first sample of the sequence.
  void reset();
  /// \brief The next sample, ±amplitude.
  double next();
  /// \brief The next \p count samples.
  std::vector<double> take(std::size_t count);
  /// \brief Period in bits, 2^n − 1.
  std::size_t periodBits() const { return period_bits_; }
  /// \brief Period in samples, (2^n − 1) · clock_divider.
  std::size_t periodSamples() const { return period_bits_ * static_cast<std::size_t>(config_.clock_divider); }
  const PrbsConfig& config() const { return config_; }

private:
  PrbsConfig config_;
  std::size_t period_bits_ = 0;
  std::uint32_t feedback_mask_ = 0;  ///< taps as bits 0..n-1 (bit k-1 for tap k)
  std::uint32_t state_ = 0;
  int hold_ = 0;  ///< samples left of the current bit
  double level_ = 0.0;
};
}  // namespace scanhead
