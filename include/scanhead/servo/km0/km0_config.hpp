/// \file km0_config.hpp
/// \brief Settings of the KM0 maintenance protocol (THESIS §2.4, SPEC §3): the excitation signal
/// and the verdict thresholds. Defaults and their derivation: config/km0.yaml.
#pragma once

#include <string>
#include <vector>

namespace scanhead
{
/// \brief The KM0 excitation signal of one axis (THESIS Fig. 2.57): small steps, large
/// (speed-saturated) steps, then ramps at many speeds, each up and down.
///
/// The target (a piecewise-constant angle) goes through the NC's joint pipeline (SPEC §2):
/// box FIR T1 → velocity saturation → box FIR T2. A step is a jump of the target with the
/// saturation at \ref max_speed_radps ("large" when the FIR T1 ramp A/T1 exceeds it); a ramp at
/// speed v is a jump of the target with the saturation set to v (THESIS: ramps are programmed
/// through the speed limit).
struct Km0SignalConfig
{
  double joint_lower_rad = -0.1745;  ///< mechanical range (URDF joint limits of galvo_x/galvo_y) [rad]
  double joint_upper_rad = 0.1745;   ///< [rad]
  double range_margin_deg = 0.5;     ///< targets stay this far inside the joint limits [deg]
  double max_speed_radps = 25.0;     ///< NC velocity saturation for steps and positioning [rad/s]
  double fir_t1_s = 260.0e-6;        ///< NC box FIR T1 [s] (0: none)
  double fir_t2_s = 125.0e-6;        ///< NC box FIR T2 [s] (0: none)
  std::vector<double> small_steps_deg = {0.02, 0.05, 0.1, 0.2};  ///< up then down from the range centre [deg]
  std::vector<double> large_steps_deg = {2.0, 5.0, 10.0, 15.0};  ///< centred on the range centre, up then down [deg]
  std::vector<double> ramp_speeds_radps = {0.5, 1.0, 2.0, 4.0, 6.0, 8.0, 10.0, 12.5, 15.0, 17.5, 20.0, 22.5, 25.0};
  double ramp_duration_s = 10.0e-3;     ///< nominal duration of each ramp (amplitude v·this, capped by the range) [s]
  double min_ramp_duration_s = 4.0e-3;  ///< a ramp shorter than this (range too small for v) is an error [s]
  double step_hold_s = 6.0e-3;  ///< time from the setpoint's arrival (|Δ|/max_speed + T1 + T2 after a step command) to
                                ///< the next command [s]
  double ramp_hold_s =
      3.0e-3;  ///< time from the setpoint's arrival (a/v + T1 + T2) after a ramp to the next command [s]
  double start_hold_s = 2.0e-3;  ///< rest before the first command [s]

  /// \throws ConfigError "km0.<field> must be ..." naming the value
  void validate() const;
};

/// \brief Tolerances of the measurements (THESIS §2.4 definitions).
struct Km0MetricConfig
{
  double start_threshold_deg = 1.0e-4;  ///< start delay: the response has moved this much [deg]
  double settling_band = 0.05;          ///< ±5 % band for settling times (of the step amplitude / steady speed)
  double plane_mm_per_deg = 24.8;       ///< mechanical deg → mm at the plane near the field centre [mm/deg]

  void validate() const;
};

/// \brief Two limits of one metric: value ≤ watch → ok; ≤ intervene → watch; above → intervene.
struct Km0Limit
{
  double watch = 0.0;
  double intervene = 0.0;
};

/// \brief Verdict thresholds, defaults as config/km0.yaml (derived there from the healthy simulated
/// galvos with margins) (THESIS §2.4: "bon fonctionnement / à surveiller / intervention").
struct Km0Thresholds
{
  // small steps (speed not saturated)
  Km0Limit small_start_delay_s{5.8e-5, 9.6e-5};
  Km0Limit small_overshoot_pct{10.8, 20.8};
  Km0Limit small_settling_time_s{6.7e-4, 1.1e-3};
  Km0Limit small_static_error_deg{1.0e-3, 5.0e-3};
  // large steps (speed saturated)
  Km0Limit large_start_delay_s{3.1e-5, 5.1e-5};
  Km0Limit large_overshoot_pct{5.8, 15.8};
  Km0Limit large_settling_excess_s{2.0e-4, 5.0e-4};  ///< settling time − |A|/max_speed [s]
  Km0Limit large_static_error_deg{1.1e-3, 5.0e-3};
  // ramps
  Km0Limit ramp_lag_s{1.6e-5, 2.7e-5};             ///< following error / speed [s]
  Km0Limit ramp_speed_error_pct{0.5, 2.0};         ///< |steady − commanded| / commanded [%]
  Km0Limit ramp_speed_settling_s{5.3e-4, 8.9e-4};  ///< ±5 % speed settling from the ramp start [s]
  Km0Limit ramp_friction_excess_pct{25.0, 60.0};   ///< (Kc·i − baseline(ω)) / baseline reference [%]

  void validate() const;
};

/// \brief Friction of the healthy machine, the reference of the friction verdict:
/// \f[ T_{f,0}(\omega) = B\omega + T_p + T_c\,\mathrm{sgn}(\omega) \f]
struct Km0FrictionBaseline
{
  bool from_servo = true;              ///< take B, Tp, Tc of the simulated axis (the values below ignored)
  double viscous_nms = 2.0e-6;         ///< B [N·m·s/rad] (the default galvos' value, galvo_params.hpp)
  double offset_torque_nm = 1.0e-6;    ///< Tp [N·m]
  double coulomb_torque_nm = 2.1e-6;   ///< Tc [N·m]
  double reference_floor_nm = 1.0e-6;  ///< denominator floor of the friction excess [N·m]

  void validate() const;
};

struct Km0Config
{
  Km0SignalConfig signal;
  Km0MetricConfig metric;
  Km0Thresholds thresholds;
  Km0FrictionBaseline baseline;

  void validate() const;
};

/// \brief Reads a Km0Config from YAML text; missing keys keep their defaults, unknown keys are
/// errors. Layout (config/km0.yaml):
/// \code
/// signal: {joint_lower_rad: -0.1745, ..., small_steps_deg: [0.02, 0.05], ramp_speeds_radps: [1, 2]}
/// metric: {start_threshold_deg: 1.0e-4, settling_band: 0.05, plane_mm_per_deg: 24.8}
/// thresholds: {small_start_delay_s: {watch: 6.0e-5, intervene: 1.0e-4}, ...}
/// baseline: {from_servo: true, viscous_nms: 0, offset_torque_nm: 0, coulomb_torque_nm: 0, reference_floor_nm: 1.0e-6}
/// \endcode
/// \throws InputError on malformed YAML or unknown keys (naming \p source), ConfigError on invalid values
Km0Config km0ConfigFromYaml(const std::string& yaml_text, const std::string& source);

/// \brief Reads \p path (empty: defaults). \throws InputError if unreadable
Km0Config loadKm0Config(const std::string& path);
}  // namespace scanhead
