/// \file hinf_loops.hpp
/// \brief Frequency analysis of one axis under its H∞ position controller (THESIS Fig. 3.5, 3.7): the loop
/// L = K G, the four transfers the weights shape (S, KS, SG, T), margins, bandwidth and θ/θref with feedforward.
#pragma once

#include <complex>
#include <string>

#include "scanhead/common/plot_hook.hpp"
#include "scanhead/servo/cascade_gains.hpp"
#include "scanhead/servo/galvo_plant.hpp"
#include "scanhead/servo/hinf/hinf_synthesis.hpp"
#include "scanhead/servo/loop_analysis.hpp"
#include "scanhead/servo/servo_config.hpp"

namespace scanhead
{
/// \brief Responses of one axis with the H∞ controller, as the servo runs it.
///
/// G(jω) = (180/π)·T_i·H_ω/i/(jω): θ [°] per i_ref [A] through the current loop T_i = L_i/(1 + L_i) of CascadeLoops
/// (its sampling delay Tc/2 included). K(jω): the implemented controller, K_s's triangle-hold equivalent at
/// z = e^{jωTc} plus the integrator's trapezoidal rule k_i(Tc/2)(z + 1)/(z − 1) (Tc = 0: the continuous K_r). With the
/// feedforward (cascade_controller.hpp), i_ref = K(θref − θ) + FF_i θref and U_ff = FF_U θref entering with the current
/// PI's output: \f[ \frac{\theta}{\theta_{ref}} = \frac{H_{\omega/i}}{s}\cdot\frac{T_i(K' + FF_i) + S_U FF_U}
///     {1 + T_i K' H_{\omega/i}/s},\qquad K' = \tfrac{180}{\pi}K. \f]
class HinfLoops
{
public:
  using Complex = std::complex<double>;
  HinfLoops(const GalvoPlantParams& plant, const CascadeGains& gains, const HinfDesign& design,
            double controller_period_s, bool voltage_feedforward = true);
  Complex plant(double w) const;                                         ///< G(jω) [°/A]
  Complex controller(double w) const;                                    ///< K_r as implemented [A/°]
  Complex openLoop(double w) const { return controller(w) * plant(w); }  ///< L = KG
  Complex closedLoop(double w, bool feedforward) const;                  ///< θ/θref
  /// \brief −d arg(θ/θref)/dω at 0 with the feedforward, = −Im(θ/θref)/ω at ω = 1e-3 rad/s [s]
  double lowFrequencyDelay() const;

private:
  CascadeLoops cascade_;   ///< plant, current loop and feedforward paths
  StateSpace k_;           ///< K_r (continuous), used when tc_ = 0
  StateSpace k_discrete_;  ///< K_s discretised (triangle hold)
  double integral_gain_;
  double tc_;
};

/// \brief What `scanhead_galvo loops --position-controller hinf` prints for one axis.
struct HinfLoopReport
{
  double gamma = 0.0;              ///< γ of the central controller
  double gamma_lower = 0.0;        ///< largest γ found infeasible
  double crossover_rad_s = 0.0;    ///< |L| = 1
  double phase_margin_deg = 0.0;   ///< 180° + arg L there (phase unwrapped from 0.1 rad/s)
  double gain_margin_db = 0.0;     ///< −20 log|L| where arg L first falls below −180° above the crossover
  double gain_margin_rad_s = 0.0;  ///< that frequency
  double bandwidth_hz = 0.0;       ///< −3 dB of T, feedback only
  double bandwidth_with_feedforward_hz = 0.0;
  double peak_s_db = 0.0, peak_ks_db = 0.0, peak_sg_db = 0.0, peak_t_db = 0.0;  ///< maxima, 0.1 rad/s .. Nyquist
  double low_frequency_delay_s = 0.0;  ///< −d arg(θ/θref)/dω at 0, feedforward included [s]
  double moved_pole_rad_s = 0.0;       ///< the central controller's pole moved to the origin
  int full_order = 0, reduced_order = 0;
};

/// \brief The figures above: margins and peaks on a log grid (400 points a decade, 0.1 rad/s up to the Nyquist
/// pulsation π/Tc or 1e7), bandwidths by closedLoopBandwidth() (loop_analysis.hpp).
/// \throws NumericalError if the loop has no gain crossover or |T| stays above −3 dB up to 1e7 rad/s
HinfLoopReport analyseHinfLoops(const GalvoPlantParams& plant, const CascadeGains& gains, const HinfDesign& design,
                                double controller_period_s, bool voltage_feedforward = true);

/// \brief −d arg(θ/θref)/dω at 0 with the feedforward and the H∞ controller [s].
double hinfLowFrequencyDelay(const GalvoPlantParams& plant, const CascadeGains& gains, const HinfDesign& design,
                             double controller_period_s, bool voltage_feedforward = true);

/// \brief YAML report of one axis (0 = x, 1 = y) under the H∞ controller synthesised from \p config (servo.hinf, the
/// axis's plant and current PI) at the controller rate: gamma, gamma_lower, orders, moved pole, integral gain,
/// crossover, phase and gain margins, bandwidths, peaks of S, KS, SG, T, low-frequency delay, and for comparison
/// the conventional (pd) structure's position crossover, margin and bandwidth. With \p out_dir: also
/// hinf_bode.csv there (frequency_hz; K full and reduced, L of hinf and pd in dB and degrees; S, KS, SG, T of hinf and
/// their templates γ/|W1|, γ/|W2|, γ/|W1W3|, γ/|W2W3|; S and T of pd), then \p plots is called with the folder.
/// \throws ConfigError on an invalid config, NumericalError if the synthesis fails
std::string hinfLoopsReportYaml(const ServoConfig& config, int axis, const std::string& out_dir = "",
                                const PlotHook& plots = {});
}  // namespace scanhead
