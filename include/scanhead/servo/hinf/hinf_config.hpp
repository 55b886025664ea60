/// \file hinf_config.hpp
/// \brief servo.hinf: the weights and settings of the H∞ position controller's synthesis (THESIS §3.2.3).
#pragma once

#include <string>

#include "scanhead/servo/hinf/state_space.hpp"

namespace scanhead
{
/// \brief A first-order weight set by its low-frequency gain G0, high-frequency gain G∞ and the pulsation ω0 where
/// its template crosses 0 dB (THESIS eq. 3.40–3.41): W = 1/template,
/// \f[ W(s) = \frac{c s + d}{a s + b},\quad a = G_\infty\sqrt{|G_0^2 - 1|},\; b = G_0\omega_0\sqrt{|G_\infty^2 - 1|},
///     c = \sqrt{|G_0^2 - 1|},\ d = \omega_0\sqrt{|G_\infty^2 - 1|} \f]
/// so |1/W| = G0 at 0, G∞ at ∞ and 1 at ω0.
struct FirstOrderWeight
{
  double g0 = 1.0;        ///< G0, template gain at low frequency
  double ginf = 1.0;      ///< G∞, template gain at high frequency
  double w0_rad_s = 1.0;  ///< ω0 [rad/s]

  StateSpace stateSpace() const;  ///< W(s), one state
  /// \throws ConfigError "<prefix>.<field> ..." (gains > 0 and ≠ 1, ω0 > 0)
  void validate(const std::string& prefix) const;
};

/// \brief servo.hinf: the synthesis settings, the same for both axes (each axis its own plant).
/// Defaults: the THESIS's weights for its Y galvo (§3.2.3, Fig. 3.5).
struct HinfConfig
{
  FirstOrderWeight w1{0.001, 1.001, 3000.0};  ///< on the error ε [°]: S below γ/|W1|
  FirstOrderWeight w2{55.0, 0.1, 5.0e5};      ///< on the command u [A]: KS below γ/|W2|
  FirstOrderWeight w3{15.0, 0.9, 300.0};      ///< shapes the input disturbance b = W3 d [A]
  /// γ-iteration stops when the feasible γ is within this fraction of an infeasible one; the central controller is
  /// taken at that feasible γ (as MATLAB's hinfsyn, which the THESIS used, with its default tolerance 0.01).
  double gamma_tolerance = 0.01;
  /// States of the implemented controller: the integrator + balanced truncation of the rest (THESIS: 9 → 8).
  int reduced_order = 8;

  /// \throws ConfigError naming servo.hinf.<field> and the value
  void validate() const;
};
}  // namespace scanhead
