/// \file cascade_controller.cpp
#include "scanhead/servo/cascade_controller.hpp"

#include <cmath>

#include "cascade_controller_update.hpp"

namespace scanhead
{
CascadeController::CascadeController(const CascadeGains& gains, double jeq_over_kc, double period_s, double supply_v,
                                     bool differentiate, const GalvoPlantParams& plant, bool voltage_feedforward)
  : differentiate_(differentiate)
  , voltage_ff_(voltage_feedforward)
{
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
}

void CascadeController::reset(double angle_rad)
{
  s_ = CascadeControllerState<double>{};
  s_.theta_ref_prev = angle_rad;
}

double CascadeController::update(double theta_ref, double omega_ref, double alpha_ref, double theta, double omega,
                                 double current)
{
  return cascadeControllerUpdate(k_, s_, differentiate_, voltage_ff_, theta_ref, omega_ref, alpha_ref, theta, omega,
                                 current);
}
}  // namespace scanhead
