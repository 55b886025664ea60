/// \file km0_protocol.hpp
/// \brief The KM0 maintenance protocol (THESIS §2.4, SPEC §3): excitation signal, run through
/// one servo axis, and the step / ramp metrics.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "scanhead/servo/km0/km0_config.hpp"

namespace scanhead
{
class AxisModel;

/// \brief What a phase of the KM0 signal is.
enum class Km0PhaseKind
{
  Positioning,  ///< a move to the start of the next test, not measured
  SmallStep,
  LargeStep,
  Ramp
};

const char* km0PhaseName(Km0PhaseKind kind);

/// \brief One phase: from the sample where the command starts to change to the next phase's.
struct Km0Phase
{
  Km0PhaseKind kind = Km0PhaseKind::Positioning;
  std::size_t begin = 0;  ///< sample index of the last sample at the old target (the command leaves it after this)
  std::size_t end = 0;    ///< one past the phase's last sample
  std::size_t steady_begin = 0;  ///< first sample of the steady window (THESIS "mid-phase" (1)) of a step
  double from_rad = 0.0;         ///< target before [rad]
  double to_rad = 0.0;           ///< target after [rad]
  double speed_radps = 0.0;      ///< velocity saturation in force during the phase [rad/s]
};

/// \brief The setpoint stream of the protocol, as the NC would send it (position, velocity,
/// acceleration per sample), and its phases.
struct Km0Signal
{
  double period_s = 1e-5;
  std::vector<double> position_rad;         ///< Q_filt2 [rad]
  std::vector<double> velocity_radps;       ///< its exact derivative [rad/s]
  std::vector<double> acceleration_radps2;  ///< [rad/s²]
  std::vector<double> target_rad;           ///< the piecewise-constant target before the filters [rad]
  std::vector<unsigned char> limited;       ///< 1 where the velocity saturation was active
  std::vector<Km0Phase> phases;
};

/// \brief Builds the signal (THESIS Fig. 2.57) at \p period_s.
///
/// Layout, c = centre of the joint range, usable half range h = (upper − lower)/2 − margin:
/// rest at c; each small step A: c → c + A → c; each large step A: positioning to c − A/2, then
/// c − A/2 → c + A/2 → c − A/2; each ramp speed v with amplitude a = min(2h, v·ramp_duration_s):
/// positioning to c − a/2, then c − a/2 → c + a/2 → c − a/2 at v. A step or positioning phase
/// lasts |Δ|/max_speed + T1 + T2 + step_hold_s (the steady window is the last half of
/// step_hold_s), a ramp phase a/v + T1 + T2 + ramp_hold_s. Every move is filtered as by
/// the NC: box T1, velocity saturation (max_speed_radps, or v in a ramp), box T2 (SPEC §2; the
/// derivatives as in nc_interpolator.hpp).
/// \throws ConfigError if the config is invalid, a step leaves the range, a ramp speed exceeds
/// max_speed_radps or its constant-speed part would be shorter than min_ramp_duration_s
Km0Signal makeKm0Signal(const Km0SignalConfig& config, double period_s);

/// \brief The measured response of the axis, one entry per setpoint sample.
struct Km0Response
{
  std::vector<double> position_rad;
  std::vector<double> velocity_radps;  ///< the model's velocity output (reported, not used by the metrics)
  std::vector<double> current_a;
};

/// \brief Runs \p signal through \p axis (reset at the first setpoint, then one step() per sample).
Km0Response runKm0(AxisModel& axis, const Km0Signal& signal);

/// \brief Metrics of one step response (THESIS Fig. 2.58). Times from the phase begin sample.
struct Km0StepMetrics
{
  Km0PhaseKind kind = Km0PhaseKind::SmallStep;
  double begin_time_s = 0.0;  ///< time of the phase begin sample [s]
  double command_from_rad = 0.0;
  double command_to_rad = 0.0;
  double initial_rad = 0.0;       ///< response at the begin sample
  double steady_rad = 0.0;        ///< (3) mean of the response over the second half of the phase
  double start_delay_s = 0.0;     ///< (4) first time |θ − θ0| > threshold (linear interpolation); NaN if never
  double overshoot_pct = 0.0;     ///< (5) max(0, peak beyond steady) / |steady − θ0| · 100
  double settling_time_s = 0.0;   ///< (7) last exit from steady ± band·|steady − θ0| (interpolated)
  double static_error_rad = 0.0;  ///< (10) command_to − steady
  double peak_speed_radps = 0.0;  ///< max |dθ/dt| (central differences) during the phase
  bool setpoint_limited = false;  ///< the NC velocity saturation was active during the phase
};

/// \brief Metrics of one ramp (THESIS Fig. 2.59). The ramp ends at the last sample of the
/// setpoint's constant-speed part; "mid-phase" is halfway between the phase begin and that end.
struct Km0RampMetrics
{
  double begin_time_s = 0.0;
  double command_speed_radps = 0.0;  ///< signed commanded speed v [rad/s]
  double command_from_rad = 0.0;
  double command_to_rad = 0.0;
  double ramp_end_time_s = 0.0;        ///< from the phase begin [s]
  double steady_speed_radps = 0.0;     ///< (2) (θ(end) − θ(mid)) / (t_end − t_mid): mean of dθ/dt
  double following_error_rad = 0.0;    ///< (4) (setpoint − θ)·sgn(v) at the ramp end (> 0: lag)
  double speed_settling_time_s = 0.0;  ///< (5) last exit of dθ/dt (central differences) from steady ± band
  double steady_current_a = 0.0;       ///< (8) mean current over [mid, end]
  double friction_torque_nm = 0.0;     ///< Kc · steady current [N·m]
};

/// \brief Step metrics from the response \p position_rad over [phase.begin, phase.end).
/// \param[in] start_threshold_rad  the start-delay threshold [rad]
/// \param[in] band  settling band, fraction of |steady − θ0|
/// \throws InputError if the phase is out of the arrays or shorter than 4 samples
Km0StepMetrics measureStep(const std::vector<double>& position_rad, const Km0Phase& phase, double period_s,
                           double start_threshold_rad, double band);

/// \brief Ramp metrics from the setpoint and response over [phase.begin, phase.end).
/// \param[in] ramp_end  index of the ramp's last constant-speed setpoint sample (begin < ramp_end < end)
/// \param[in] kc_nm_per_a  torque constant Kc [N·m/A]
Km0RampMetrics measureRamp(const std::vector<double>& setpoint_rad, const std::vector<double>& position_rad,
                           const std::vector<double>& current_a, const Km0Phase& phase, std::size_t ramp_end,
                           double period_s, double band, double kc_nm_per_a);

/// \brief Index of the last sample of the constant-speed part of a ramp phase: the last sample
/// of the phase whose setpoint velocity equals the phase's speed within 1e-9 relative.
/// \throws InputError if the phase has no such sample
std::size_t rampEndIndex(const Km0Signal& signal, const Km0Phase& phase);

/// \brief Least-squares fit of Kc·i = B·ω + Tp + Tc·sgn(ω) over the ramps.
struct Km0FrictionFit
{
  double viscous_nms = 0.0;
  double offset_torque_nm = 0.0;
  double coulomb_torque_nm = 0.0;
  double rms_residual_nm = 0.0;
  bool valid = false;  ///< false unless both signs and ≥ 2 speeds per sign
};
Km0FrictionFit fitFriction(const std::vector<Km0RampMetrics>& ramps);

/// \brief All metrics of one KM0 run.
struct Km0Results
{
  std::vector<Km0StepMetrics> steps;
  std::vector<Km0RampMetrics> ramps;
  Km0FrictionFit friction_fit;
};

/// \brief Measures every step and ramp phase of \p signal in \p response.
Km0Results measureKm0(const Km0Signal& signal, const Km0Response& response, const Km0MetricConfig& metric,
                      double kc_nm_per_a);
}  // namespace scanhead
