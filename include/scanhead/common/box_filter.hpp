/// \file box_filter.hpp
/// \brief Moving-average ("box") FIR filter of unit area and exact duration (SPEC §2.3).
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <vector>

namespace scanhead
{
/// \brief Causal box filter of exact duration T on a sampled signal of N channels.
///
/// The input samples x_k (at t_k = k·Ts) are read as the piecewise-linear signal x(t) through
/// them; the output at t_n is its exact mean over the last T seconds (SPEC §2.3, NC §2.2):
/// \f[ y(t_n) = \frac{1}{T}\int_{t_n - T}^{t_n} x(\tau)\,d\tau \f]
/// With T = (m + f)·Ts (m whole periods, 0 <= f < 1) this is the trapezoid rule over the m
/// whole periods plus the exact partial trapezoid over the fraction f, i.e. the taps
/// \f[ y_n = \frac{1}{m+f}\Big(\tfrac12 x_n + \sum_{k=1}^{m-1} x_{n-k}
///     + (\tfrac12 + f - \tfrac{f^2}{2})\,x_{n-m} + \tfrac{f^2}{2}\,x_{n-m-1}\Big) \f]
/// (for m = 0: (f - f²/2)·x_n + (f²/2)·x_{n-1}, over f). The taps sum to m + f: unit DC gain.
/// A ramp comes out delayed by exactly T/2. Before the first push the input is held at the
/// value given to reset() (machine at rest). T = 0 is the identity.
///
/// The filter also gives the exact time derivative of its output,
/// \f[ \dot y(t_n) = \frac{x(t_n) - x(t_n - T)}{T} \f]
/// with x(t_n − T) linearly interpolated at the fractional delay; for T = 0 the limit
/// T → 0⁺ of that expression, the backward difference (x_n − x_{n−1})/Ts.
///
/// Storage: ceil(T/Ts) + 2 samples at most (doubled so the window is contiguous); no
/// allocation per sample.
///
/// \tparam N number of channels (instantiated for 1, 2 and 4)
template <int N>
class BoxFilter
{
public:
  using Vector = Eigen::Matrix<double, N, 1>;

  /// \brief Identity filter (T = 0) at Ts = 1e-5 s.
  BoxFilter();

  /// \param[in] duration_s T >= 0 [s], any value (not rounded to whole samples)
  /// \param[in] period_s   Ts > 0 [s]
  /// \throws ConfigError if T < 0, Ts <= 0 or either is not finite
  BoxFilter(double duration_s, double period_s);

  /// \brief Forgets the past: the input is held at \p initial before the next push.
  void reset(const Vector& initial);

  /// \brief Appends the next input sample x_n.
  void push(const Vector& x)
  {
    head_ = (head_ + 1 == taps_) ? 0 : head_ + 1;
    buffer_.col(head_) = x;
    buffer_.col(head_ + taps_) = x;
  }

  /// \brief push(x[i]), then average() into average[i] and derivative() into derivative[i], for
  /// i = 0 .. count−1: the same numbers bit for bit, computed a chunk at a time (the tap sums
  /// across the samples, which are independent, instead of one sample's taps after another: a
  /// vector loop instead of a chain of dependent additions). \p derivative may be null; only the
  /// first \p average_channels channels of \p average are written (the others are left as they are).
  void pushBlock(const Vector* x, std::size_t count, Vector* average, Vector* derivative, int average_channels = N);

  /// \brief y(t_n), the mean of x over [t_n − T, t_n].
  ///
  /// Evaluated as x_n + Σ w_k (x_{n−k} − x_n) (the taps sum to 1): a constant input comes out
  /// bit-exact (the machine at rest stays exactly at rest) and rounding scales with the
  /// variation over the window rather than with |x|.
  Vector average() const
  {
    const Vector latest = sampleAgo(0);
    Vector y = Vector::Zero();
    const double* w = weights_.data();
    for (std::size_t j = 0; j < taps_; ++j)
    {
      y.noalias() += w[j] * (buffer_.col(head_ + 1 + j) - latest);
    }
    return latest + y;
  }

  /// \brief x(t_n − T), the input linearly interpolated at the (fractional) delay T.
  Vector delayed() const { return (1.0 - frac_) * sampleAgo(whole_) + frac_ * sampleAgo(whole_ + 1); }

  /// \brief Exact derivative of the output: (x_n − x(t_n − T))/T; (x_n − x_{n−1})/Ts if T = 0.
  Vector derivative() const
  {
    if (identity_)
    {
      return (sampleAgo(0) - sampleAgo(1)) / period_s_;
    }
    return (sampleAgo(0) - delayed()) / duration_s_;
  }

  /// \brief The input sample k periods ago (k = 0: the latest), k < taps().
  auto sampleAgo(std::size_t k) const { return buffer_.col(head_ + taps_ - k); }

  double duration() const { return duration_s_; }  ///< T actually realised [s]
  double period() const { return period_s_; }      ///< Ts [s]
  std::size_t taps() const { return taps_; }       ///< samples kept (ring size)

private:
  double period_s_ = 1e-5;
  double duration_s_ = 0.0;  ///< (m + f)·Ts, after snapping T/Ts to an integer within 1e-9
  std::size_t whole_ = 0;    ///< m = floor(T/Ts)
  double frac_ = 0.0;        ///< f = T/Ts − m
  bool identity_ = true;
  std::size_t taps_ = 2;         ///< m + 2
  std::vector<double> weights_;  ///< weights_[j] multiplies x_{n − (taps−1−j)}, scaled by 1/(m+f)
  Eigen::Matrix<double, N, Eigen::Dynamic> buffer_;  ///< 2·taps columns, each sample written twice
  std::size_t head_ = 0;
  std::vector<double> block_history_;  ///< pushBlock: one channel's window history and new samples
  std::vector<double> block_sums_;     ///< pushBlock: its tap sums
};

extern template class BoxFilter<1>;
extern template class BoxFilter<2>;
extern template class BoxFilter<4>;
}  // namespace scanhead
