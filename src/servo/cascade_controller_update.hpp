/// \file cascade_controller_update.hpp
/// \brief The one sample of CascadeController (equations in cascade_controller.hpp), written once
/// for one axis (T = double) and for two axes in the lanes of a vector (T = lanes::Double2): the
/// lockstep servo gives each axis the bits of the scalar controller.
#pragma once

#include "lanes.hpp"
#include "scanhead/servo/cascade_controller.hpp"

namespace scanhead
{
/// \brief The feedforward signals ω_ff = s/(1+τf s) θref and α_ff = s²/(1+τf s)² θref of one sample.
template <class T>
inline void feedforwardSignals(const CascadeControllerCoefficients<T>& k, CascadeControllerState<T>& s,
                               bool differentiate, T theta_ref, T omega_ref, T alpha_ref, T& w_ff, T& a_ff)
{
  if (differentiate)
  {
    // s/(1 + τf s) ramp-invariant (first-order-hold equivalent): exact slope for ramps, no ringing;
    // backward difference at τf = 0 (a = 0).
    s.lp1 = k.lp_a * s.lp1 + k.diff_c * (theta_ref - s.theta_ref_prev);
    s.lp2 = k.lp_a * s.lp2 + k.diff_c * (s.lp1 - s.d1_prev);
    s.theta_ref_prev = theta_ref;
    s.d1_prev = s.lp1;
    w_ff = s.lp1;
    a_ff = s.lp2;
  }
  else
  {
    s.lp1 = k.lp_a * s.lp1 + k.lp_b * omega_ref;
    s.lp2 = k.lp_a * s.lp2 + k.lp_b * alpha_ref;
    s.lp3 = k.lp_a * s.lp3 + k.lp_b * s.lp2;  // FF_i has the filter twice
    w_ff = s.lp1;
    a_ff = s.lp3;
  }
}

/// \brief The voltage feedforward U_ff = R i_ff + L di_ff/dt + Ke ω_ff into s.u_ff (when on), and i_ff remembered.
template <class T>
inline void voltageFeedforward(const CascadeControllerCoefficients<T>& k, CascadeControllerState<T>& s, bool voltage_ff,
                               T w_ff, T i_ff)
{
  if (voltage_ff)
  {
    // di_ff/dt: the filter's own discrete derivative (backward difference of the filtered i_ff) —
    // the continuous derivative in the filter's state, (x − LP(x))/τf, is the slope just after the
    // sampled input steps and overshoots the interval's mean slope (measured: worse corner errors).
    const T di_ff = (i_ff - s.i_ff_prev) / k.period_s;
    s.u_ff = k.r_ohm * i_ff + k.l_h * di_ff + k.ke_k1 * w_ff;
  }
  s.i_ff_prev = i_ff;
}

/// \brief The voltage feedforward and the current PI from the current reference s.i_ref and the current
/// feedforward \p i_ff already in it; returns the unsaturated voltage and the current PI's new integral.
template <class T>
inline T currentLoop(const CascadeControllerCoefficients<T>& k, CascadeControllerState<T>& s, bool voltage_ff, T w_ff,
                     T i_ff, T current, T& int_i_new)
{
  voltageFeedforward(k, s, voltage_ff, w_ff, i_ff);
  // Current PI.
  const T e_i = s.i_ref - current;
  int_i_new = s.int_i + k.ci * (e_i + s.e_i_prev);
  s.e_i_prev = e_i;
  return k.kii * (e_i + int_i_new) + s.u_ff;
}

/// \brief One controller sample; returns the voltage saturated to ±supply [V].
///
/// The loops are linear between the measurements: each reference is its gain times its error plus terms known before
/// this sample's θ, ω, i (the states' memories and the feedforwards), e.g. ω_ref = Kθ(e_θ + d_k) + K1 w_ff =
/// Kθ(1 + b)·e_θ + [Kθ(a d_{k−1} − b e_{θ,k−1}) + K1 w_ff] with the PD's d_k = a d_{k−1} + b(e_θ − e_{θ,k−1}).
/// Written so, the measurements reach u through three multiply-adds instead of ~20 dependent operations (the servo
/// step is a recursion: this chain is its speed); the states are then updated off that path. The same equations as
/// the cascade_controller.hpp forms, rounded differently (~1 ulp).
/// \param[in] differentiate, voltage_ff  the controller's modes (the same for every lane)
template <class T>
inline T cascadeControllerUpdate(const CascadeControllerCoefficients<T>& k, CascadeControllerState<T>& s,
                                 bool differentiate, bool voltage_ff, T theta_ref, T omega_ref, T alpha_ref, T theta,
                                 T omega, T current)
{
  using lanes::both;
  using lanes::clampTo;
  using lanes::magnitude;
  using lanes::select;
  T w_ff, a_ff;
  feedforwardSignals(k, s, differentiate, theta_ref, omega_ref, alpha_ref, w_ff, a_ff);
  const T i_ff = k.k2_jeq * a_ff;
  voltageFeedforward(k, s, voltage_ff, w_ff, i_ff);
  // The references' parts known before the measurements.
  const T q_w = k.ktheta * (k.pd_a * s.d_state - k.pd_b * s.e_theta_prev) + k.k1 * w_ff;
  const T q_i = k.kiw * (s.int_w + k.cw * s.e_w_prev) + i_ff;
  const T q_u = k.kii * (s.int_i + k.ci * s.e_i_prev) + s.u_ff;
  // Position PD, speed PI, current PI: from the measurements to u.
  const T e_theta = theta_ref - theta;
  s.omega_ref = k.p_w * e_theta + q_w;
  const T e_w = s.omega_ref - omega;
  s.i_ref = k.p_i * e_w + q_i;
  const T e_i = s.i_ref - current;
  const T u = k.p_u * e_i + q_u;
  // The states.
  s.d_state = k.pd_a * s.d_state + k.pd_b * (e_theta - s.e_theta_prev);
  s.e_theta_prev = e_theta;
  const T int_w_new = s.int_w + k.cw * (e_w + s.e_w_prev);
  s.e_w_prev = e_w;
  const T int_i_new = s.int_i + k.ci * (e_i + s.e_i_prev);
  s.e_i_prev = e_i;
  // Anti-windup: conditional integration.
  const auto saturated = both(magnitude(u) > k.supply_v, e_i * u > T{});
  s.int_i = select(saturated, s.int_i, int_i_new);
  s.int_w = select(saturated, s.int_w, int_w_new);
  return clampTo(u, -k.supply_v, k.supply_v);
}
}  // namespace scanhead
