/// \file galvo_identification.hpp
/// \brief Identification of one galvo's base-model parameters (R, L, Kc = Ke, B, Jeq) from a PRBS
/// experiment on the simulated plant (SPEC §3; THESIS §2.2.1.2 and app. A): the experiment, the
/// spectral estimates and the fit of the two transfer forms of transfer_forms.hpp,
/// \f[ \frac{\theta}{i}(s) = \frac{G_1}{s(1 + \tau_1 s)},\qquad
///     \frac{i}{U}(s) = \frac{G_2(1 + \tau_1 s)}{1 + \sigma s + \pi s^2}, \f]
/// by levenbergMarquardt() (common/levenberg_marquardt.hpp). The report and the Bode CSV are in
/// identification_report.hpp.
#pragma once

#include <cstddef>
#include <vector>

#include "scanhead/servo/galvo_plant.hpp"
#include "scanhead/servo/identification/prbs.hpp"
#include "scanhead/servo/identification/spectral_estimate.hpp"
#include "scanhead/servo/identification/transfer_forms.hpp"

namespace scanhead
{
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
  PrbsConfig prbs{16, 1, 1.0e-3};   ///< order, clock divider, amplitude [V] (small: see ramp)
  double sample_period_s = 1.0e-5;  ///< T [s], the controller / sampling rate
  int settle_periods = 1;           ///< PRBS periods discarded (transient), raised to cover 10 loop time constants
  int averaged_periods = 3;         ///< P, Welch segments (one PRBS period each)
  SpectralWindow window = SpectralWindow::Rectangular;
  double position_loop_hz = 2.0;        ///< crossover of the stabilising P loop [Hz]; 0 = open loop
  double ramp_rad_per_s = 0.05;         ///< slope of the loop's setpoint ramp [rad/s]; the PRBS speed
                                        ///< ripple (≈ ±0.012 rad/s per mV on the default Y galvo) must stay below it
  bool zero_friction = false;           ///< run with Tp = Tc = 0 (else as configured)
  double theta_fit_max_hz = 3000.0;     ///< upper end of the θ/i fit band [Hz]
  double current_fit_max_hz = 20000.0;  ///< upper end of the i/U fit band [Hz]
  double bode_check_max_hz = 2000.0;    ///< band of the fitted-vs-true Bode comparison [Hz]

  /// \throws ConfigError "identification.<field> ..." naming the value
  void validate() const;
};

/// \brief Everything the experiment and the fits produced.
struct IdentificationResult
{
  FrequencyResponse theta_per_current;    ///< measured θ/i [rad/A] (H1, coherence of Δθ vs i)
  FrequencyResponse current_per_voltage;  ///< measured i/U [A/V]
  TransferForms fitted;
  TransferForms truth_forms;  ///< transferFormsOf(truth)
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
  std::size_t samples = 0;  ///< simulated samples
  int settle_periods = 0;   ///< periods discarded (settle_periods, raised to 10 loop time constants)
  double angle_min_rad = 0.0, angle_max_rad = 0.0;  ///< excursion during the experiment
  std::size_t velocity_sign_changes =
      0;  ///< sign changes of the rigid speed ω_r in the averaged part (where Coulomb friction flips)
  std::size_t saturated_samples = 0;     ///< samples with |U| beyond the supply (nonlinear)
  double position_gain_v_per_rad = 0.0;  ///< Kp of the stabilising loop [V/rad]
};

/// \brief Runs the experiment on GalvoPlant(\p truth), estimates, fits, recovers.
/// \throws ConfigError on an invalid config; NumericalError if a fit fails
IdentificationResult identifyGalvo(const GalvoPlantParams& truth, const IdentificationConfig& config);
}  // namespace scanhead
