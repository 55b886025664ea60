/// \file cascade_controller.hpp
/// \brief The discrete cascade controller of one galvo axis (SPEC §3, THESIS Fig. 2.26–2.29).
#pragma once

#include "scanhead/servo/cascade_gains.hpp"
#include "scanhead/servo/galvo_plant.hpp"
#include "scanhead/servo/hinf/hinf_position_controller.hpp"

namespace scanhead
{
/// \brief Current PI, speed PI and position PD in cascade with speed and current feedforward,
/// run every period T from the sampled setpoint and measurements; outputs the driver voltage.
///
/// Discretisation (T = controller period):
/// - PI \f$K(1 + 1/(T_i s))\f$: Tustin, \f$I_k = I_{k-1} + \frac{T}{2T_i}(e_k + e_{k-1})\f$,
///   \f$u_k = K(e_k + I_k)\f$;
/// - PD \f$K_\theta(1 + T_d s/(1 + \tau_d s))\f$, \f$\tau_d = T_d/100\f$: Tustin,
///   \f$y_k = \frac{2\tau_d - T}{2\tau_d + T}y_{k-1} + \frac{2T_d}{2\tau_d + T}(e_k - e_{k-1})\f$;
/// - feedforward filters \f$1/(1 + \tau_f s)\f$: step-invariant pole \f$a = e^{-T/\tau_f}\f$,
///   \f$y_k = a y_{k-1} + (1 - a)x_k\f$ (no ringing whatever T/τf; exact pass-through at τf = 0).
///   "nc" mode: \f$\omega_{ff} = K_1\,LP(\dot\theta_{ref})\f$, \f$i_{ff} =
///   K_2\frac{J_{eq}}{K_c}LP(LP(\ddot\theta_{ref}))\f$ with the NC's exact derivatives: the THESIS transfer functions,
///   without differentiating a sampled signal (no half-sample lag, no noise gain). "differentiate" mode: the THESIS's
///   \f$s/(1 + \tau_f s)\f$ applied to θref, discretised ramp-invariant (first-order-hold equivalent:
///   \f$d_k = a d_{k-1} + \frac{1 - a}{T}(\theta_k - \theta_{k-1})\f$, exact on ramps; a backward
///   difference at τf = 0), twice for the acceleration.
/// - voltage feedforward (\p voltage_feedforward; design choice of this project, not in the THESIS):
///   \f$U_{ff} = R\,i_{ff} + L\,\frac{di_{ff}}{dt} + K_e\,\omega_{ff}\f$ added to the current PI's output
///   before the saturation, with \f$i_{ff} = K_2\frac{J_{eq}}{K_c}\alpha_{ff}\f$, \f$\omega_{ff} = K_1 w_{ff}\f$
///   the current and speed feedforwards above: the current follows \f$i_{ff}\f$ without waiting for the
///   current loop (crossover 1e4 rad/s). \f$\frac{di_{ff}}{dt}\f$ is the filter's own discrete derivative,
///   the backward difference \f$(i_{ff,k} - i_{ff,k-1})/T\f$ (= the filtered backward difference of the
///   NC's acceleration; the continuous derivative in the filter's state, \f$(x - LP(x))/\tau_f\f$, is the
///   slope just after the sampled input steps and overshoots: corner errors −25 %/−18 % instead of
///   −6 %/−1 %). Why: with the pure THESIS structure the current loop lags FFi, the outer loops fight it, θ/θref peaks
///   +7 dB near 1 kHz and on the NC paper's corner (2 m/s, 53.13°) the actual corner error is 19.8 µm against the
///   setpoint's 62.7 µm, the actual path 108 µm from the setpoint; the NC paper's bench shows the actual
///   path ≈ the filtered setpoint. Off: the pure THESIS structure.
/// - anti-windup: when the voltage saturates (|U| > supply) and the current error drives it
///   further, the current and speed integrators keep their previous values (conditional integration).
/// - servo.position_controller: hinf (THESIS Fig. 3.7): the position PD and the speed PI replaced by the H∞
///   controller, \f$i_{ref} = K_\infty(\theta_{ref} - \theta) + i_{ff}\f$ (HinfPositionController, error in degrees);
///   the feedforwards and the current PI as above, its integral held by the same anti-windup.
/// \brief Constants of CascadeController::update, precomputed from the gains and the period
/// (T = double; or a vector of doubles, one lane per axis, when two controllers run in lockstep):
/// the discretised gains above, and p_w, p_i, p_u, the gains of each loop's error in its own sample
/// (cascadeControllerUpdate: the measurements reach the voltage through three multiply-adds).
template <class T>
struct CascadeControllerCoefficients
{
  T lp_a;      ///< a = e^{-T/τf}
  T lp_b;      ///< 1 − a
  T diff_c;    ///< (1 − a)/T ("differentiate" mode)
  T pd_a;      ///< (2τd − T)/(2τd + T)
  T pd_b;      ///< 2Tdθ/(2τd + T)
  T ktheta;    ///< Kθ
  T k1;        ///< K1
  T k2_jeq;    ///< K2·Jeq/Kc
  T kiw;       ///< Kiω
  T cw;        ///< T/(2Tiω)
  T ci;        ///< T/(2Tii)
  T kii;       ///< Kii
  T period_s;  ///< T
  T r_ohm;     ///< R
  T l_h;       ///< L
  T ke_k1;     ///< Ke·K1
  T supply_v;  ///< saturation [V]
  T p_w;       ///< Kθ(1 + pd_b): ω_ref per radian of e_θ this sample
  T p_i;       ///< Kiω(1 + cw): i_ref per rad/s of e_ω this sample
  T p_u;       ///< Kii(1 + ci): U per ampere of e_i this sample
};

/// \brief The controller's memory (T as in CascadeControllerCoefficients).
template <class T>
struct CascadeControllerState
{
  T e_theta_prev, d_state;
  T e_w_prev, int_w;
  T e_i_prev, int_i;
  T lp1, lp2, lp3, theta_ref_prev, d1_prev;
  T i_ff_prev;  ///< last i_ff (discrete derivative) [A]
  T omega_ref, i_ref, u_ff;
};

class CascadeController
{
public:
  /// \param[in] gains  validated gains
  /// \param[in] jeq_over_kc  Jeq/Kc of the current feedforward [A/(rad/s²)]
  /// \param[in] period_s  controller period T [s]
  /// \param[in] supply_v  driver saturation [V]
  /// \param[in] differentiate  true: feedforward from the setpoint's filtered derivatives
  /// \param[in] plant  R, L, Ke (= Kc) of the voltage feedforward
  /// \param[in] voltage_feedforward  add \f$U_{ff}\f$ (false: the pure THESIS structure)
  /// \param[in] hinf  the H∞ position controller's design (servo.position_controller: hinf), or null for the PD
  CascadeController(const CascadeGains& gains, double jeq_over_kc, double period_s, double supply_v, bool differentiate,
                    const GalvoPlantParams& plant, bool voltage_feedforward, const HinfDesign* hinf = nullptr);
  /// \brief At rest at \p angle_rad: integrators, filters and memories cleared (no derivative kick).
  void reset(double angle_rad);
  /// \brief One controller sample: returns the voltage command, saturated to ±supply [V].
  /// \param[in] theta_ref, omega_ref, alpha_ref  setpoint and its NC derivatives [rad, rad/s, rad/s²]
  /// \param[in] theta, omega, current  measured angle, speed, current [rad, rad/s, A]
  double update(double theta_ref, double omega_ref, double alpha_ref, double theta, double omega, double current);
  double speedReference() const { return s_.omega_ref; }  ///< last ω_ref [rad/s]
  double currentReference() const { return s_.i_ref; }    ///< last i_ref [A]
  double voltageFeedforward() const { return s_.u_ff; }   ///< last U_ff [V] (0 when off)
  bool hinf() const { return hinf_; }                     ///< the H∞ position controller runs

private:
  friend class CascadeAxis;  ///< steps two controllers in lockstep (CascadeAxis::stepPair)

  /// \brief update() with the H∞ position controller.
  double updateHinf(double theta_ref, double omega_ref, double alpha_ref, double theta, double current);

  bool differentiate_;
  bool voltage_ff_;
  bool hinf_ = false;
  HinfPositionController hinf_controller_;
  CascadeControllerCoefficients<double> k_{};
  CascadeControllerState<double> s_{};
};
}  // namespace scanhead
