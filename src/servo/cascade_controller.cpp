/// \file cascade_controller.cpp
#include "scanhead/servo/cascade_controller.hpp"

#include <algorithm>
#include <cmath>

namespace scanhead
{
CascadeController::CascadeController(const CascadeGains& gains, double jeq_over_kc, double period_s, double supply_v,
                                     bool differentiate, const GalvoPlantParams& plant, bool voltage_feedforward)
  : g_(gains)
  , jeq_over_kc_(jeq_over_kc)
  , period_s_(period_s)
  , supply_v_(supply_v)
  , differentiate_(differentiate)
  , r_ohm_(plant.resistance_ohm)
  , l_h_(plant.inductance_h)
  , ke_(plant.torque_constant_nm_per_a)
  , voltage_ff_(voltage_feedforward)
{
  const double t = period_s_;
  lp_a_ = g_.tauf_s > 0.0 ? std::exp(-t / g_.tauf_s) : 0.0;
  const double tau_d = g_.tdtheta_s / 100.0;
  if (g_.tdtheta_s > 0.0)
  {
    pd_a_ = (2.0 * tau_d - t) / (2.0 * tau_d + t);
    pd_b_ = 2.0 * g_.tdtheta_s / (2.0 * tau_d + t);
  }
  ci_ = t / (2.0 * g_.tii_s);
  cw_ = t / (2.0 * g_.tiw_s);
}

void CascadeController::reset(double angle_rad)
{
  e_theta_prev_ = d_state_ = 0.0;
  e_w_prev_ = int_w_ = 0.0;
  e_i_prev_ = int_i_ = 0.0;
  lp1_ = lp2_ = lp3_ = d1_prev_ = 0.0;
  theta_ref_prev_ = angle_rad;
  omega_ref_ = i_ref_ = u_ff_ = i_ff_prev_ = 0.0;
}

double CascadeController::update(double theta_ref, double omega_ref, double alpha_ref, double theta, double omega,
                                 double current)
{
  // Feedforward signals: ω_ff = s/(1+τf s) θref, α_ff = s²/(1+τf s)² θref.
  double w_ff = 0.0, a_ff = 0.0;
  const double a = lp_a_;
  if (differentiate_)
  {
    // s/(1 + τf s) ramp-invariant (first-order-hold equivalent): exact slope for ramps, no ringing;
    // backward difference at τf = 0 (a = 0).
    const double c = (1.0 - a) / period_s_;
    lp1_ = a * lp1_ + c * (theta_ref - theta_ref_prev_);
    lp2_ = a * lp2_ + c * (lp1_ - d1_prev_);
    theta_ref_prev_ = theta_ref;
    d1_prev_ = lp1_;
    w_ff = lp1_;
    a_ff = lp2_;
  }
  else
  {
    lp1_ = a * lp1_ + (1.0 - a) * omega_ref;
    lp2_ = a * lp2_ + (1.0 - a) * alpha_ref;
    lp3_ = a * lp3_ + (1.0 - a) * lp2_;  // FF_i has the filter twice
    w_ff = lp1_;
    a_ff = lp3_;
  }
  // Position PD.
  const double e_theta = theta_ref - theta;
  d_state_ = pd_a_ * d_state_ + pd_b_ * (e_theta - e_theta_prev_);
  e_theta_prev_ = e_theta;
  omega_ref_ = g_.ktheta * (e_theta + d_state_) + g_.k1 * w_ff;
  // Speed PI.
  const double e_w = omega_ref_ - omega;
  const double int_w_new = int_w_ + cw_ * (e_w + e_w_prev_);
  e_w_prev_ = e_w;
  const double i_ff = g_.k2 * jeq_over_kc_ * a_ff;
  i_ref_ = g_.kiw * (e_w + int_w_new) + i_ff;
  // Voltage feedforward U_ff = R i_ff + L di_ff/dt + Ke ω_ff.
  if (voltage_ff_)
  {
    // di_ff/dt: the filter's own discrete derivative (backward difference of the filtered i_ff) —
    // the continuous derivative in the filter's state, (x − LP(x))/τf, is the slope just after the
    // sampled input steps and overshoots the interval's mean slope (measured: worse corner errors).
    const double di_ff = (i_ff - i_ff_prev_) / period_s_;
    u_ff_ = r_ohm_ * i_ff + l_h_ * di_ff + ke_ * g_.k1 * w_ff;
  }
  i_ff_prev_ = i_ff;
  // Current PI.
  const double e_i = i_ref_ - current;
  const double int_i_new = int_i_ + ci_ * (e_i + e_i_prev_);
  e_i_prev_ = e_i;
  const double u = g_.kii * (e_i + int_i_new) + u_ff_;
  const bool saturated = std::abs(u) > supply_v_ && e_i * u > 0.0;
  if (!saturated)
  {
    int_i_ = int_i_new;
    int_w_ = int_w_new;
  }
  return std::clamp(u, -supply_v_, supply_v_);
}
}  // namespace scanhead
