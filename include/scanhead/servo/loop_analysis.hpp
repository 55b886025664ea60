/// \file loop_analysis.hpp
/// \brief Frequency analysis and synthesis of a galvo's cascaded loops from its linear model
/// (SPEC §3; THESIS §2.2.2.2, eq. 2.28–2.33).
///
/// Linear model (friction Tp, Tc and saturation left out, as the THESIS's synthesis model, Fig. 2.33):
/// \f[ H_{\omega/i} = \frac{K_c}{J_{eq}s + B} + \frac{K_r s}{s^2 + 2\xi_r\omega_{res}s + \omega_{res}^2},\qquad
///     H_{i/U} = \frac{1}{Ls + R + K_e H_{\omega/i}} \f]
/// (eq. 2.31 rearranged). The discrete controller's sample-and-hold is the delay \f$e^{-sT_c/2}\f$ in
/// the current loop (the only place a held output enters the plant; the outer loops act at the same
/// instants). Loops: \f$L_i = REG_i e^{-sT_c/2} H_{i/U}\f$, \f$T_i = L_i/(1 + L_i)\f$;
/// \f$L_\omega = REG_\omega T_i H_{\omega/i}\f$, \f$T_\omega = L_\omega/(1 + L_\omega)\f$;
/// \f$L_\theta = REG_\theta T_\omega / s\f$. Closed loop, feedback only (THESIS Fig. 2.40)
/// \f$L_\theta/(1 + L_\theta)\f$; with feedforward (THESIS eq. 2.32–2.33)
/// \f[ \frac{\theta}{\theta_{ref}} = \frac{(REG_\theta + FF_\omega)T_\omega + (FF_i\,T_i + FF_U S_U) H_{\omega/i}/(1 +
/// L_\omega)}{s + REG_\theta T_\omega} \f] with the voltage feedforward of this project (cascade_controller.hpp,
/// servo.voltage_feedforward) \f$FF_U = (R + Ls)FF_i + K_e FF_\omega\f$ entering with the current PI's output, \f$S_U =
/// e^{-sT_c/2}H_{i/U}/(1 + L_i)\f$ (\f$FF_U = 0\f$ without it: the THESIS's eq. 2.32–2.33). The feedback-only loops,
/// margins and bandwidth do not depend on it. The feedforward's 1/(1 + τf s) is taken as the controller realises it
/// (cascade_controller.hpp, NC derivatives): \f$(1 - a)/(1 - a e^{-sT_c})\f$, \f$a = e^{-T_c/\tau_f}\f$.
#pragma once

#include <complex>
#include <functional>
#include <string>

#include "scanhead/servo/cascade_gains.hpp"
#include "scanhead/servo/galvo_plant.hpp"
#include "scanhead/servo/servo_config.hpp"

namespace scanhead
{
/// \brief Frequency responses of one axis's linear model under its controller.
class CascadeLoops
{
public:
  /// \param[in] controller_period_s  Tc [s] (0: continuous controller, no sampling delay)
  /// \param[in] voltage_feedforward  include FF_U in closedLoop(w, true)
  CascadeLoops(const GalvoPlantParams& plant, const CascadeGains& gains, double controller_period_s,
               bool voltage_feedforward = true);
  using Complex = std::complex<double>;
  Complex currentPerVoltage(double w) const;  ///< H_{i/U}(jw), plant
  Complex speedPerCurrent(double w) const;    ///< H_{ω/i}(jw), plant
  Complex currentOpenLoop(double w) const;    ///< L_i(jw)
  Complex speedOpenLoop(double w) const;      ///< L_ω(jw)
  Complex positionOpenLoop(double w) const;   ///< L_θ(jw)
  /// \brief θ/θref(jw), with or without the feedforward paths (K1, K2 as configured)
  Complex closedLoop(double w, bool feedforward) const;
  /// \brief The feedforward paths per θref at jw, as the controller realises them: FF_ω (K1), FF_i (K2) and the
  /// voltage FF_U (0 without the voltage feedforward).
  struct Feedforward
  {
    Complex speed, current, voltage;
  };
  Feedforward feedforward(double w) const;

private:
  GalvoPlantParams p_;
  CascadeGains g_;
  double tc_;
  bool voltage_ff_;
};

/// \brief Crossover (first downward crossing of |L| = 1) and phase margin 180° + arg L there, with
/// the phase unwrapped continuously from low frequency.
struct LoopMargin
{
  double crossover_rad_s = 0.0;
  double phase_margin_deg = 0.0;
};

/// \brief What `scanhead_galvo loops` prints for one axis.
struct LoopReport
{
  LoopMargin current, speed, position;
  double bandwidth_hz = 0.0;                   ///< −3 dB of θ/θref, feedback only (THESIS Fig. 2.40) [Hz]
  double bandwidth_with_feedforward_hz = 0.0;  ///< −3 dB of θ/θref with FFω, FFi [Hz]
  double peak_with_feedforward_db = 0.0;       ///< max |θ/θref| with feedforward, 1 Hz..50 kHz [dB]
  double low_frequency_delay_s = 0.0;          ///< −d arg(θ/θref)/dω at 0, feedforward included [s]
  double mode_frequency_hz = 0.0;              ///< peak of |H_ω/i − rigid part| (the flexible mode) [Hz]
  double controller_rate_hz = 0.0;
};

/// \brief First downward crossing of |f| = 1 on a log grid (200 points/decade, 1 rad/s..1e7 rad/s),
/// refined by bisection; margin from the unwrapped phase.
/// \throws NumericalError if there is no crossing
LoopMargin loopMargin(const std::function<std::complex<double>(double)>& open_loop);

/// \brief Lowest frequency [Hz] where |θ/θref| falls below 1/√2 (grid + bisection, 1 rad/s..1e7 rad/s).
/// \throws NumericalError if none below 1e7 rad/s
double closedLoopBandwidth(const std::function<std::complex<double>(double)>& closed_loop);
/// \brief closedLoopBandwidth() of the cascade's θ/θref, with or without the feedforward.
double closedLoopBandwidth(const CascadeLoops& loops, bool feedforward);

/// \brief −d arg(θ/θref)/dω at 0 with the feedforward, = −Im H(jω)/ω at ω = 1e-3 rad/s
/// (H = 1 − jωτ + O(ω²)) [s]: one evaluation, cheap enough for constructors.
double lowFrequencyDelay(const GalvoPlantParams& plant, const CascadeGains& gains, double controller_period_s,
                         bool voltage_feedforward = true);

/// \brief Figures of the axis at the given controller period.
/// \param[in] voltage_feedforward  with the voltage feedforward (changes only the with-feedforward figures)
LoopReport analyseLoops(const GalvoPlantParams& plant, const CascadeGains& gains, double controller_period_s,
                        bool voltage_feedforward = true);

/// \brief Targets of the frequency synthesis (THESIS §2.2.2.2).
struct LoopTargets
{
  double current_crossover_rad_s = 1.0e4;
  double current_margin_deg = 65.0;
  double speed_crossover_rad_s = 5000.0;
  double speed_margin_deg = 65.0;  ///< the speed PI's target when speed_integral_time_s = 0, else its floor
  /// Tiω given instead of found from the margin [s] (0: from speed_margin_deg). The THESIS's refinement
  /// (§2.2.2, Tableau 2.1) set it to 0.005 s on Y, the margin rule's 0.04 s being "not fast enough"
  /// against the dry friction; this project's stored gains use it (issue 15's fit, README "Servo friction").
  double speed_integral_time_s = 0.0;
  double position_crossover_rad_s = 3000.0;
  double position_margin_deg = 75.0;
  /// \brief All three crossovers multiplied by \p k, a given Tiω divided by it (margins kept).
  LoopTargets scaled(double k) const;
};

/// \brief The THESIS's refined speed-loop integral time on Y (Tableau 2.1) [s].
constexpr double kThesisSpeedIntegralTime_s = 0.005;

/// \brief The targets of the stored gains (galvo_params.hpp) for the Y axis: the default crossovers and
/// margins with the THESIS's refined Tiω; X uses them scaled by kGalvoXCrossoverScale.
inline LoopTargets storedGainTargets()
{
  LoopTargets t;
  t.speed_integral_time_s = kThesisSpeedIntegralTime_s;
  return t;
}

/// \brief Frequency synthesis of the THESIS (§2.2.2.2), in closed form per loop, inner to outer,
/// each on the model with the loops inside it closed and the sampling delay Tc/2:
/// PI: the integral time sets the margin, \f$\arg REG(j\omega_c) = -\arctan\frac{1}{\omega_c T_i}
/// = \Delta\Phi - 180° - \arg H(j\omega_c)\f$ (Ti = ∞ if the plant alone has more margin), unless the
/// speed PI's is given (LoopTargets::speed_integral_time_s); then
/// \f$K = 1/|(1 + 1/(j\omega_c T_i))H(j\omega_c)|\f$ puts the crossover at ωc.
/// PD: Tdθ by bisection on the phase lead \f$\arg(1 + T_d j\omega_c/(1 + T_d j\omega_c/100))\f$ on its
/// decreasing branch (Tdθ ≥ 1/(0.1005 ωc), past the lead maximum — the THESIS's solution, Tdθ ≈ 0.1 s),
/// then Kθ for |L_θ(jωc)| = 1. τf, K1, K2 are copied from \p base.
/// \throws NumericalError if a target is unreachable, or a given Tiω leaves the speed loop less than
/// speed_margin_deg
CascadeGains synthesiseGains(const GalvoPlantParams& plant, const LoopTargets& targets, double controller_period_s,
                             const CascadeGains& base = CascadeGains{});

/// \brief YAML report of one axis (0 = x, 1 = y) of \p config at its controller rate: the keys
/// bandwidth_hz, position_crossover_rad_s, position_phase_margin_deg, speed_crossover_rad_s,
/// speed_phase_margin_deg, current_crossover_rad_s, current_phase_margin_deg,
/// bandwidth_with_feedforward_hz, peak_with_feedforward_db, low_frequency_delay_s,
/// mode_frequency_hz, controller_rate_hz, axis (with servo.voltage_feedforward as configured). \throws ConfigError on
/// an invalid config
std::string loopsReportYaml(const ServoConfig& config, int axis);
}  // namespace scanhead
