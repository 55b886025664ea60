/// \file cascade_controller.cpp
#include "scanhead/servo/cascade_controller.hpp"

#include <algorithm>
#include <cmath>

#include "cascade_controller_update.hpp"

namespace scanhead
{
CascadeController::CascadeController(const CascadeGains& gains, double jeq_over_kc, double period_s, double supply_v,
                                     bool differentiate, const GalvoPlantParams& plant, bool voltage_feedforward,
                                     const HinfDesign* hinf)
  : differentiate_(differentiate)
  , voltage_ff_(voltage_feedforward)
  , hinf_(hinf != nullptr)
{
  if (hinf_)
    hinf_controller_ = HinfPositionController(*hinf, period_s);
  const double t = period_s;
  CascadeControllerCoefficients<double>& k = k_;
  k.lp_a = gains.tauf_s > 0.0 ? std::exp(-t / gains.tauf_s) : 0.0;
  k.lp_b = 1.0 - k.lp_a;
  k.diff_c = (1.0 - k.lp_a) / t;
  const double tau_d = gains.tdtheta_s / 100.0;
  k.pd_a = 0.0;
  k.pd_b = 0.0;
  if (gains.tdtheta_s > 0.0)
  {
    k.pd_a = (2.0 * tau_d - t) / (2.0 * tau_d + t);
    k.pd_b = 2.0 * gains.tdtheta_s / (2.0 * tau_d + t);
  }
  k.ktheta = gains.ktheta;
  k.k1 = gains.k1;
  k.k2_jeq = gains.k2 * jeq_over_kc;
  k.kiw = gains.kiw;
  k.cw = t / (2.0 * gains.tiw_s);
  k.ci = t / (2.0 * gains.tii_s);
  k.kii = gains.kii;
  k.period_s = t;
  k.r_ohm = plant.resistance_ohm;
  k.l_h = plant.inductance_h;
  k.ke_k1 = plant.torque_constant_nm_per_a * gains.k1;
  k.supply_v = supply_v;
  k.p_w = k.ktheta * (1.0 + k.pd_b);
  k.p_i = k.kiw * (1.0 + k.cw);
  k.p_u = k.kii * (1.0 + k.ci);
}

void CascadeController::reset(double angle_rad)
{
  s_ = CascadeControllerState<double>{};
  s_.theta_ref_prev = angle_rad;
  hinf_controller_.reset();
}

double CascadeController::update(double theta_ref, double omega_ref, double alpha_ref, double theta, double omega,
                                 double current)
{
  if (hinf_)
    return updateHinf(theta_ref, omega_ref, alpha_ref, theta, current);
  return cascadeControllerUpdate(k_, s_, differentiate_, voltage_ff_, theta_ref, omega_ref, alpha_ref, theta, omega,
                                 current);
}

double CascadeController::updateHinf(double theta_ref, double omega_ref, double alpha_ref, double theta, double current)
{
  double w_ff, a_ff;
  feedforwardSignals(k_, s_, differentiate_, theta_ref, omega_ref, alpha_ref, w_ff, a_ff);
  const double i_ff = k_.k2_jeq * a_ff;
  s_.omega_ref = k_.k1 * w_ff;  // no speed loop: reported as the speed feedforward
  s_.i_ref = hinf_controller_.update((theta_ref - theta) * (180.0 / M_PI)) + i_ff;
  double int_i_new;
  const double u = currentLoop(k_, s_, voltage_ff_, w_ff, i_ff, current, int_i_new);
  const bool saturated = std::abs(u) > k_.supply_v && s_.e_i_prev * u > 0.0;
  if (!saturated)
    s_.int_i = int_i_new;
  hinf_controller_.commit(saturated);
  return std::clamp(u, -k_.supply_v, k_.supply_v);
}
}  // namespace scanhead
