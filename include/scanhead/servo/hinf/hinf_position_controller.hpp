/// \file hinf_position_controller.hpp
/// \brief The H∞ position controller of one axis as the servo runs it: discrete, at the controller period
/// (THESIS Fig. 3.7: it replaces the position PD and the speed PI; current PI and feedforward kept).
#pragma once

#include <Eigen/Core>

#include "scanhead/servo/hinf/hinf_synthesis.hpp"

namespace scanhead
{
/// \brief K_r(s) = k_i/s + K_s(s) of HinfDesign discretised by the triangle hold at the controller period T (the
/// THESIS's discretisation, §3.4; triangleHold() in state_space.hpp):
/// \f$I_k = I_{k-1} + k_i\frac{T}{2}(\varepsilon_k + \varepsilon_{k-1})\f$ (the integrator's exact triangle-hold
/// equivalent, the trapezoidal rule) and K_s's x⁺ = A_d x + B_d ε, y = C_d x + D_d ε; i_ref = I_k + y_k.
/// Input the angle error in degrees (the synthesis unit), output the current reference [A]. The integral is the
/// state held by the anti-windup (as the cascade's integrators: CascadeController).
class HinfPositionController
{
public:
  static constexpr int kMaxOrder = 16;  ///< states of K_s (fixed capacity: no allocation per sample)
  HinfPositionController() = default;
  /// \throws NumericalError if K_s has more than kMaxOrder states
  HinfPositionController(const HinfDesign& design, double period_s);
  void reset();
  /// \brief i_ref [A] for the error \p error_deg [°]; the integral's update is pending until commit().
  double update(double error_deg);
  /// \brief Takes the pending update (\p hold_integral: keep the integral as it was, the anti-windup).
  void commit(bool hold_integral);
  double integral() const { return integral_; }  ///< I [A]

private:
  using Matrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxOrder, kMaxOrder>;
  using Vector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxOrder, 1>;
  Matrix a_;
  Vector b_;
  Vector c_;  ///< C_dᵀ
  double d_ = 0.0;
  double half_ki_t_ = 0.0;  ///< k_i·T/2
  Vector x_;
  double integral_ = 0.0, integral_new_ = 0.0, error_prev_ = 0.0, error_ = 0.0;
};
}  // namespace scanhead
