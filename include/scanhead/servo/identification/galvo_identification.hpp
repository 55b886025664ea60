/// \file galvo_identification.hpp
/// \brief Identification of one galvo's base-model parameters (R, L, Kc = Ke, B, Jeq) from a PRBS
/// experiment on the simulated plant (SPEC §3; THESIS §2.2.1.2 and app. A).
///
/// The two transfer functions of the base model (rigid rotor, no friction offsets, no mode):
/// \f[ \frac{\theta}{i}(s) = \frac{K_c/B}{s\,(1 + \frac{J_{eq}}{B}s)} = \frac{G_1}{s(1 + \tau_1 s)}, \f]
/// \f[ \frac{i}{U}(s) = \frac{J_{eq}s + B}{(R + Ls)(J_{eq}s + B) + K_eK_c}
///     = \frac{G_2(1 + \tau_1 s)}{(1 + \tau_2 s)(1 + \tau_3 s)}, \f]
/// whence \f$G_1 = K_c/B\f$, \f$\tau_1 = J_{eq}/B\f$, \f$G_2 = B/(BR + K_eK_c)\f$,
/// \f$\tau_2\tau_3 = G_2 L\tau_1\f$, \f$\tau_2 + \tau_3 = G_2(L + R\tau_1)\f$.
#pragma once

#include <complex>
#include <cstddef>
#include <string>
#include <vector>

#include "scanhead/servo/galvo_plant.hpp"
#include "scanhead/servo/identification/prbs.hpp"
#include "scanhead/servo/identification/spectral_estimate.hpp"

namespace scanhead
{
/// \brief The parameter set (G1, τ1, G2, τ2, τ3) of the two fitted forms (THESIS eq. 2.10, 2.11).
///
/// The i/U denominator is kept as \f$(1 + \tau_2 s)(1 + \tau_3 s) = 1 + \sigma s + \pi s^2\f$,
/// σ = τ2 + τ3, π = τ2τ3: with a small viscous friction B and a large Kc²/R the two poles are a
/// complex pair (τ2, τ3 complex conjugates; the default Y galvo has ζ ≈ 0.9), which the real
/// (σ, π) describe continuously. tau2()/tau3() give the roots, complex if so.
struct TransferForms
{
  double g1_rad_per_as = 0.0;   ///< G1 = Kc/B [rad/(A·s)]
  double tau1_s = 0.0;          ///< τ1 = Jeq/B [s]
  double g2_a_per_v = 0.0;      ///< G2 = B/(BR + KeKc) [A/V]
  double tau_sum_s = 0.0;       ///< σ = τ2 + τ3 = G2(L + Rτ1) [s]
  double tau_product_s2 = 0.0;  ///< π = τ2τ3 = G2Lτ1 [s²]

  /// \brief τ2, the root of τ² − στ + π = 0 with the larger real part (then the larger
  /// imaginary part) [s]; τ3 = its partner.
  std::complex<double> tau2() const;
  std::complex<double> tau3() const;
};

/// \brief The five physical parameters the identification recovers.
struct PhysicalParams
{
  double resistance_ohm = 0.0;             ///< R [Ω]
  double inductance_h = 0.0;               ///< L [H]
  double torque_constant_nm_per_a = 0.0;   ///< Kc = Ke [N·m/A]
  double viscous_nms = 0.0;                ///< B [N·m·s/rad]
  double inertia_kgm2 = 0.0;               ///< Jeq [kg·m²]
};

/// \brief (G1, τ1, G2, σ, π) of a plant's base model, from the relations in the file comment.
/// Friction offsets and the flexible mode are not part of the base model and are ignored.
TransferForms transferFormsOf(const GalvoPlantParams& plant);

/// \brief THESIS eq. (2.13) (SPEC §3): with \f$r_1 = 1/\tau_2,\ r_2 = 1/\tau_3,\ a = \tau_1\f$,
/// \f[ c = \frac{1}{G_2 a r_1 r_2},\quad b = \frac{a c (r_1 + r_2) - c}{a},\quad
///     d = \frac{(ba + c)^2 - 4acb - (ac)^2(r_1 - r_2)^2}{4ac}, \f]
/// \f[ L = c,\ R = b,\ K_c = K_e = d/G_1,\ B = K_c/G_1,\ J_{eq} = aB. \f]
/// Evaluated as written in complex arithmetic (r1, r2 conjugates for a complex pole pair: every
/// quantity above is then real, r1 + r2 = σ/π, r1r2 = 1/π, (r1 − r2)² = (σ² − 4π)/π²).
/// Checked against the plant equations: c = L from τ2τ3 = G2Lτ1; b = R from τ2 + τ3 = G2(L + Rτ1);
/// d simplifies to \f$ac\,r_1r_2 - b = 1/G_2 - R = K_eK_c/B\f$. So (2.13) is right; the thesis'
/// printed eq. (2.9) and (2.12) drop a factor R (i/U lacks 1/R, "1 + KeKc/B" should read
/// "R + KeKc/B", "Jeq/B·L/R" should read "Jeq/B·L", "Jeq/B + L/R" should read "L + R·Jeq/B").
/// \throws NumericalError if a parameter comes out non-positive or non-finite
PhysicalParams recoverPhysicalParams(const TransferForms& forms);

/// \brief \f$G_1/(s(1 + \tau_1 s))\f$ at \f$s = j2\pi f\f$ [rad/A].
std::complex<double> thetaPerCurrent(const TransferForms& forms, double f_hz);
/// \brief \f$G_2(1 + \tau_1 s)/(1 + \sigma s + \pi s^2)\f$ at \f$s = j2\pi f\f$ [A/V].
std::complex<double> currentPerVoltage(const TransferForms& forms, double f_hz);

/// \brief The identification experiment and fit.
///
/// Experiment: voltage U[n] = ±a (PRBS) + Kp·(θref(nT) − θ[n]), held over each period T, on the
/// simulated plant (GalvoPlant); θref = ramp_rad_per_s · (t − t_end/2), the ramp centred on 0
/// (the plant starts at rest at θref(0)). The weak proportional position loop
/// (crossover position_loop_hz, Kp from the nominal DC gain ω/U = Kc/(BR + Kc²)) keeps the
/// integrating plant in its range; it does not bias the estimates because θ = (θ/i)·i and
/// i = (i/U)·U hold whatever drives U (noise-free simulation). With Coulomb friction, a ramp
/// faster than the PRBS speed ripple keeps sgn(ω) constant, so Tc acts as a constant torque and the
/// plant stays linear around the ramp.
///
/// Estimation: H1 with Welch averaging, one segment per PRBS period after settle_periods
/// (rectangular window, no overlap: a synchronous average, exact on the PRBS lines of a periodic
/// steady state). θ/i is estimated through the first difference Δθ[n] = θ[n] − θ[n−1], which is
/// periodic even while θ drifts, then divided by \f$1 - e^{-j2\pi fT}\f$.
///
/// Fit: Levenberg–Marquardt on the log parameters, residual \f$r_k = w_k(G(f_k)/\hat G_k - 1)\f$,
/// \f$w_k = \gamma_k^2/\sqrt{f_k}\f$ (coherence × equal weight per decade). θ/i is fitted with the
/// continuous form (the current is smooth); i/U with the exact zero-order-hold equivalent of the
/// form (the driver holds U over T), τ1 taken from the θ/i fit. Initial guesses from asymptotes.
struct IdentificationConfig
{
  PrbsConfig prbs{16, 1, 1.0e-3};    ///< order, clock divider, amplitude [V] (small: see ramp)
  double sample_period_s = 1.0e-5;   ///< T [s], the controller / sampling rate
  int settle_periods = 1;            ///< PRBS periods discarded (transient), raised to cover 10 loop time constants
  int averaged_periods = 3;          ///< P, Welch segments (one PRBS period each)
  SpectralWindow window = SpectralWindow::Rectangular;
  double position_loop_hz = 2.0;     ///< crossover of the stabilising P loop [Hz]; 0 = open loop
  double ramp_rad_per_s = 0.05;      ///< slope of the loop's setpoint ramp [rad/s]; the PRBS speed
                                     ///< ripple (≈ ±0.012 rad/s per mV on the default Y galvo) must stay below it
  bool zero_friction = false;        ///< run with Tp = Tc = 0 (else as configured)
  double theta_fit_max_hz = 3000.0;  ///< upper end of the θ/i fit band [Hz]
  double current_fit_max_hz = 20000.0;  ///< upper end of the i/U fit band [Hz]
  double bode_check_max_hz = 2000.0; ///< band of the fitted-vs-true Bode comparison [Hz]

  /// \throws ConfigError "identification.<field> ..." naming the value
  void validate() const;
};

/// \brief Everything the experiment and the fits produced.
struct IdentificationResult
{
  FrequencyResponse theta_per_current;    ///< measured θ/i [rad/A] (H1, coherence of Δθ vs i)
  FrequencyResponse current_per_voltage;  ///< measured i/U [A/V]
  TransferForms fitted;
  TransferForms truth_forms;              ///< transferFormsOf(truth)
  PhysicalParams identified;
  PhysicalParams truth;
  double theta_fit_rms_residual = 0.0;    ///< RMS of |G/Ĝ − 1| over the θ/i fit band
  double current_fit_rms_residual = 0.0;  ///< RMS of |G/Ĝ − 1| over the i/U fit band
  int theta_fit_iterations = 0;
  int current_fit_iterations = 0;
  double theta_bode_max_error_db = 0.0;   ///< max |dB(fit) − dB(true plant)| up to bode_check_max_hz
  double theta_bode_max_error_deg = 0.0;  ///< same for the phase [deg]
  double current_bode_max_error_db = 0.0;
  double current_bode_max_error_deg = 0.0;
  std::size_t samples = 0;                ///< simulated samples
  int settle_periods = 0;                 ///< periods discarded (settle_periods, raised to 10 loop time constants)
  double angle_min_rad = 0.0, angle_max_rad = 0.0;  ///< excursion during the experiment
  std::size_t velocity_sign_changes = 0;  ///< sign changes of the rigid speed ω_r in the averaged part (where Coulomb friction flips)
  std::size_t saturated_samples = 0;      ///< samples with |U| beyond the supply (nonlinear)
  double position_gain_v_per_rad = 0.0;   ///< Kp of the stabilising loop [V/rad]
};

/// \brief True plant frequency responses (continuous, including the flexible mode):
/// \f$\theta/i = K_c/(s(J_{eq}s + B)) + K_r/(s^2 + 2\xi_r\omega_{res}s + \omega_{res}^2)\f$.
std::complex<double> trueThetaPerCurrent(const GalvoPlantParams& plant, double f_hz);
/// \brief \f$i/U = 1/(R + Ls + K_e\,\omega/i)\f$ with ω/i as in galvo_plant.hpp (back-EMF from the
/// mirror speed, THESIS eq. 2.30, so the flexible mode shows in i/U too).
std::complex<double> trueCurrentPerVoltage(const GalvoPlantParams& plant, double f_hz);

/// \brief Runs the experiment on GalvoPlant(\p truth), estimates, fits, recovers.
/// \throws ConfigError on an invalid config; NumericalError if a fit fails
IdentificationResult identifyGalvo(const GalvoPlantParams& truth, const IdentificationConfig& config);

/// \brief identifyGalvo() as YAML: experiment, fitted forms and residuals, true / identified
/// R_ohm, L_h, Kc_nm_per_a, B_nms, Jeq_kgm2 and their relative errors, Bode check. If \p out_dir
/// is non-empty, writes out_dir/bode.csv and out_dir/identification.yaml and runs
/// scripts/plot_bode.py on them (bode_theta_current.png, bode_current_voltage.png); a failing
/// plot (no matplotlib) only prints a warning.
/// \throws InputError if out_dir cannot be written
std::string identificationReport(const GalvoPlantParams& truth, const IdentificationConfig& config,
                                 const std::string& out_dir);

/// \brief The Bode CSV: one row per kept bin (log-thinned), columns frequency_hz, then for θ/i and
/// i/U the measured, fitted and true magnitude [dB] and phase [deg], and the coherence.
std::string bodeCsv(const IdentificationResult& result, const GalvoPlantParams& truth);
}  // namespace scanhead
