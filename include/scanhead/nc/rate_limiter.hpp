/// \file rate_limiter.hpp
/// \brief Velocity saturation of a sampled joint signal, per axis (SPEC §2.4).
#pragma once

#include <Eigen/Core>

namespace scanhead
{
/// \brief Rate limiter: each axis moves at most v_max·Ts per sample (SPEC §2.4, between FIR T1
/// and FIR T2):
/// \f[ s_n = s_{n-1} + \mathrm{clamp}(z_n - s_{n-1},\,-v_{max} T_s,\,v_{max} T_s) \f]
/// It also carries the velocity of the signal: where the axis is not limited the input's
/// velocity passes through (clamped to ±v_max), where it is limited the velocity is ±v_max
/// (the sign of the step).
class RateLimiter
{
public:
  /// \param[in] max_rate  v_max > 0 [unit/s] (rad/s in the NC)
  /// \param[in] period_s  Ts > 0 [s]
  /// \throws ConfigError if either is not finite and > 0
  RateLimiter(double max_rate, double period_s);
  RateLimiter()
    : RateLimiter(1.0, 1e-5)
  {
  }

  /// \brief The output starts at rest at \p initial.
  void reset(const Eigen::Vector2d& initial) { value_ = initial; }

  /// \brief One sample.
  /// \param[in]  z      input sample z_n
  /// \param[in]  z_dot  velocity of the input at t_n [unit/s]
  /// \param[out] s      limited sample s_n
  /// \param[out] s_dot  its velocity [unit/s]
  /// \return true if an axis was limited at this sample
  bool step(const Eigen::Vector2d& z, const Eigen::Vector2d& z_dot, Eigen::Vector2d& s, Eigen::Vector2d& s_dot)
  {
    bool limited = false;
    for (int i = 0; i < 2; ++i)
    {
      const double dz = z[i] - value_[i];
      if (dz > max_step_)
      {
        value_[i] += max_step_;
        s_dot[i] = max_rate_;
        limited = true;
      }
      else if (dz < -max_step_)
      {
        value_[i] -= max_step_;
        s_dot[i] = -max_rate_;
        limited = true;
      }
      else
      {
        value_[i] = z[i];
        s_dot[i] = z_dot[i] > max_rate_ ? max_rate_ : (z_dot[i] < -max_rate_ ? -max_rate_ : z_dot[i]);
      }
    }
    s = value_;
    return limited;
  }

  double maxRate() const { return max_rate_; }  ///< v_max [unit/s]
  double maxStep() const { return max_step_; }  ///< v_max·Ts [unit]

private:
  double max_rate_;
  double max_step_;
  Eigen::Vector2d value_ = Eigen::Vector2d::Zero();
};
}  // namespace scanhead
