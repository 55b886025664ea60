/// \file km0_report.hpp
/// \brief KM0 verdicts (ok / watch / intervene), the YAML report and the CSV files for the plots
/// (THESIS §2.4: a rating that plans the next action: "bon fonctionnement", "à surveiller",
/// "nécessité d'intervention").
#pragma once

#include <string>

#include "scanhead/common/plot_hook.hpp"
#include "scanhead/servo/km0/km0_config.hpp"
#include "scanhead/servo/km0/km0_protocol.hpp"
#include "scanhead/servo/servo_config.hpp"

namespace scanhead
{
enum class Km0Verdict
{
  Ok = 0,
  Watch = 1,
  Intervene = 2
};

const char* km0VerdictName(Km0Verdict verdict);

/// \brief value ≤ watch → Ok; ≤ intervene → Watch; above, or NaN → Intervene.
Km0Verdict km0Verdict(double value, const Km0Limit& limit);

/// \brief What the report needs to know about the axis besides its response.
struct Km0AxisInfo
{
  std::string name = "x";                  ///< "x" or "y"
  std::string model;                       ///< servo model name (for the report)
  double torque_constant_nm_per_a = 0.01;  ///< Kc, converts the current to torque [N·m/A]
  double viscous_nms = 0.0;                ///< the axis' configured B [N·m·s/rad] (model line of the plots)
  double offset_torque_nm = 0.0;           ///< Tp [N·m]
  double coulomb_torque_nm = 0.0;          ///< Tc [N·m]
};

/// \brief Torque constant and friction of \p axis (0 = x, 1 = y) of \p servo, as the model uses them.
Km0AxisInfo km0AxisInfo(const ServoConfig& servo, int axis);

/// \brief The baseline friction the verdict compares with: the config's values, or the axis' own
/// (Km0FrictionBaseline::from_servo).
Km0FrictionBaseline km0Baseline(const Km0Config& config, const Km0AxisInfo& info);

/// \brief The KM0 report as YAML: settings, every step and ramp with its metrics and verdicts,
/// the friction fit, the overall verdict (the worst one) and \p files.
std::string km0ReportYaml(const Km0Results& results, const Km0Config& config, const Km0AxisInfo& info, double period_s,
                          const std::vector<std::string>& files = {});

/// \brief Overall verdict of a run (the worst of all metrics).
Km0Verdict km0OverallVerdict(const Km0Results& results, const Km0Config& config, const Km0AxisInfo& info);

/// \brief Writes km0_signal.csv (every sample), km0_steps.csv, km0_ramps.csv into \p out_dir
/// (created if needed). \throws InputError if a file cannot be written
void writeKm0Csv(const Km0Signal& signal, const Km0Response& response, const Km0Results& results,
                 const Km0Config& config, const Km0AxisInfo& info, const std::string& out_dir);

/// \brief Runs the whole protocol on \p axis of \p servo and writes the report into \p out_dir:
/// km0_report.yaml and the CSV files above; then, if \p plots is set, calls it on out_dir (the
/// tools pass the hook that runs scripts/plot_km0.py: km0_signal.png, km0_ramps.png,
/// km0_steps.png, km0_friction.png, km0_following_error.png) and lists the plots it made in
/// km0_report.yaml.
/// The axis is made by makeAxisModel(servo, axis, period_s) (the model servo.model names).
/// \param[in] axis  0 = x (galvo_x), 1 = y (galvo_y)
/// \param[in] plots  "data written, make the plots now" (it may read km0_report.yaml); empty: no plots
/// \return the YAML report (the text of km0_report.yaml)
/// \throws ConfigError on invalid settings, InputError if out_dir cannot be written
std::string km0Report(const ServoConfig& servo, int axis, double period_s, const Km0Config& config,
                      const std::string& out_dir, const PlotHook& plots = {});
}  // namespace scanhead
