/// \file km0_report.cpp
/// \brief KM0 verdicts, YAML report, CSV files, and the one-call protocol run.
#include "scanhead/servo/km0/km0_report.hpp"
#include "scanhead/common/text_file.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>

#include "scanhead/common/errors.hpp"
#include "scanhead/common/number_text.hpp"
#include "scanhead/servo/galvo_servo.hpp"

namespace scanhead
{
namespace fs = std::filesystem;

namespace
{
constexpr double kPi = 3.14159265358979323846;
constexpr double kDegPerRad = 180.0 / kPi;

/// A number for YAML/CSV: 9 significant digits ("%.9g"), NaN as .nan (YAML) or nan (CSV).
std::string num(double v, bool yaml = true)
{
  if (std::isnan(v))
    return yaml ? ".nan" : "nan";
  if (std::isinf(v))
    return v > 0 ? (yaml ? ".inf" : "inf") : (yaml ? "-.inf" : "-inf");
  std::string text = significantText(v, 9);
  // YAML 1.1 readers (PyYAML) take "2e-06" for a string: write "2.0e-06".
  const std::size_t e = text.find('e');
  if (yaml && e != std::string::npos && text.find('.') == std::string::npos)
    text.insert(e, ".0");
  return text;
}

double sgn(double v)
{
  return v > 0.0 ? 1.0 : (v < 0.0 ? -1.0 : 0.0);
}

double baselineTorque(const Km0FrictionBaseline& b, double omega)
{
  return b.viscous_nms * omega + b.offset_torque_nm + b.coulomb_torque_nm * sgn(omega);
}

/// Derived ramp quantities used by verdicts, YAML and CSV.
struct RampDerived
{
  double speed_error_pct;
  double lag_s;
  double baseline_nm;
  double friction_excess_pct;
};

RampDerived derive(const Km0RampMetrics& r, const Km0FrictionBaseline& b)
{
  RampDerived d;
  const double v = r.command_speed_radps;
  d.speed_error_pct = 100.0 * (r.steady_speed_radps - v) / std::abs(v);
  d.lag_s = r.following_error_rad / std::abs(v);
  d.baseline_nm = baselineTorque(b, r.steady_speed_radps);
  d.friction_excess_pct =
      100.0 * (r.friction_torque_nm - d.baseline_nm) / std::max(std::abs(d.baseline_nm), b.reference_floor_nm);
  return d;
}

struct Graded
{
  const char* name;
  double value;
  Km0Verdict verdict;
};

std::vector<Graded> gradeStep(const Km0StepMetrics& s, const Km0Thresholds& t, double max_speed)
{
  const bool small = s.kind == Km0PhaseKind::SmallStep;
  const double static_deg = std::abs(s.static_error_rad) * kDegPerRad;
  if (small)
  {
    return {{"start_delay_s", s.start_delay_s, km0Verdict(s.start_delay_s, t.small_start_delay_s)},
            {"overshoot_pct", s.overshoot_pct, km0Verdict(s.overshoot_pct, t.small_overshoot_pct)},
            {"settling_time_s", s.settling_time_s, km0Verdict(s.settling_time_s, t.small_settling_time_s)},
            {"static_error_deg", static_deg, km0Verdict(static_deg, t.small_static_error_deg)}};
  }
  const double excess = s.settling_time_s - std::abs(s.command_to_rad - s.command_from_rad) / max_speed;
  return {{"start_delay_s", s.start_delay_s, km0Verdict(s.start_delay_s, t.large_start_delay_s)},
          {"overshoot_pct", s.overshoot_pct, km0Verdict(s.overshoot_pct, t.large_overshoot_pct)},
          {"settling_excess_s", excess, km0Verdict(excess, t.large_settling_excess_s)},
          {"static_error_deg", static_deg, km0Verdict(static_deg, t.large_static_error_deg)}};
}

std::vector<Graded> gradeRamp(const Km0RampMetrics& r, const RampDerived& d, const Km0Thresholds& t)
{
  return {
      {"lag_s", d.lag_s, km0Verdict(d.lag_s, t.ramp_lag_s)},
      {"speed_error_pct", std::abs(d.speed_error_pct), km0Verdict(std::abs(d.speed_error_pct), t.ramp_speed_error_pct)},
      {"speed_settling_s", r.speed_settling_time_s, km0Verdict(r.speed_settling_time_s, t.ramp_speed_settling_s)},
      {"friction_excess_pct", std::abs(d.friction_excess_pct),
       km0Verdict(std::abs(d.friction_excess_pct), t.ramp_friction_excess_pct)}};
}

Km0Verdict worst(const std::vector<Graded>& g)
{
  Km0Verdict w = Km0Verdict::Ok;
  for (const Graded& x : g)
    w = std::max(w, x.verdict);
  return w;
}

std::string verdictMap(const std::vector<Graded>& g)
{
  std::string out = "{";
  for (std::size_t i = 0; i < g.size(); ++i)
    out += std::string(i ? ", " : "") + g[i].name + ": " + km0VerdictName(g[i].verdict);
  return out + "}";
}

/// True if the following error at the ramp ends increases with |speed| (ramps sorted by speed;
/// equal speeds, up and down, are averaged).
bool followingErrorGrows(const std::vector<Km0RampMetrics>& ramps)
{
  std::vector<std::pair<double, double>> by_speed;
  for (const Km0RampMetrics& r : ramps)
  {
    const double v = std::abs(r.command_speed_radps);
    auto it = std::find_if(by_speed.begin(), by_speed.end(), [&](const auto& p) { return p.first == v; });
    if (it == by_speed.end())
      by_speed.emplace_back(v, r.following_error_rad);
    else
      it->second = 0.5 * (it->second + r.following_error_rad);
  }
  std::sort(by_speed.begin(), by_speed.end());
  for (std::size_t i = 1; i < by_speed.size(); ++i)
  {
    if (!(by_speed[i].second > by_speed[i - 1].second))
      return false;
  }
  return by_speed.size() >= 2;
}

}  // namespace

const char* km0VerdictName(Km0Verdict verdict)
{
  switch (verdict)
  {
    case Km0Verdict::Ok:
      return "ok";
    case Km0Verdict::Watch:
      return "watch";
    case Km0Verdict::Intervene:
      return "intervene";
  }
  return "intervene";
}

Km0Verdict km0Verdict(double value, const Km0Limit& limit)
{
  if (value <= limit.watch)
    return Km0Verdict::Ok;
  if (value <= limit.intervene)
    return Km0Verdict::Watch;
  return Km0Verdict::Intervene;  // also NaN: a metric that could not be measured
}

Km0AxisInfo km0AxisInfo(const ServoConfig& servo, int axis)
{
  const AxisLoopConfig& a = axis == 0 ? servo.x : servo.y;
  Km0AxisInfo info;
  info.name = axis == 0 ? "x" : "y";
  info.model = servo.model;
  info.torque_constant_nm_per_a = a.plant.torque_constant_nm_per_a;
  if (servo.model == "closed_loop_3rd_order")
  {
    // That model reports the current of the rigid inertia only (i = θ''/(Kc/Jeq)): no friction.
    return info;
  }
  info.viscous_nms = a.plant.viscous_nms;
  info.offset_torque_nm = a.plant.offset_torque_nm;
  info.coulomb_torque_nm = a.plant.coulomb_torque_nm;
  return info;
}

Km0FrictionBaseline km0Baseline(const Km0Config& config, const Km0AxisInfo& info)
{
  Km0FrictionBaseline b = config.baseline;
  if (b.from_servo)
  {
    b.viscous_nms = info.viscous_nms;
    b.offset_torque_nm = info.offset_torque_nm;
    b.coulomb_torque_nm = info.coulomb_torque_nm;
  }
  return b;
}

Km0Verdict km0OverallVerdict(const Km0Results& results, const Km0Config& config, const Km0AxisInfo& info)
{
  const Km0FrictionBaseline b = km0Baseline(config, info);
  Km0Verdict w = Km0Verdict::Ok;
  for (const Km0StepMetrics& s : results.steps)
    w = std::max(w, worst(gradeStep(s, config.thresholds, config.signal.max_speed_radps)));
  for (const Km0RampMetrics& r : results.ramps)
    w = std::max(w, worst(gradeRamp(r, derive(r, b), config.thresholds)));
  return w;
}

std::string km0ReportYaml(const Km0Results& results, const Km0Config& config, const Km0AxisInfo& info, double period_s,
                          const std::vector<std::string>& files)
{
  const Km0FrictionBaseline b = km0Baseline(config, info);
  const double mm = config.metric.plane_mm_per_deg;
  int counts[3] = {0, 0, 0};
  std::ostringstream y;
  std::ostringstream body;

  auto stepsSection = [&](Km0PhaseKind kind, const char* title) {
    body << title << ":\n";
    bool any = false;
    for (const Km0StepMetrics& s : results.steps)
    {
      if (s.kind != kind)
        continue;
      any = true;
      const std::vector<Graded> g = gradeStep(s, config.thresholds, config.signal.max_speed_radps);
      for (const Graded& x : g)
        ++counts[static_cast<int>(x.verdict)];
      const double a_deg = (s.command_to_rad - s.command_from_rad) * kDegPerRad;
      body << "  - {t_s: " << num(s.begin_time_s) << ", amplitude_deg: " << num(a_deg)
           << ", amplitude_mm: " << num(a_deg * mm) << ", command_to_deg: " << num(s.command_to_rad * kDegPerRad)
           << ", steady_deg: " << num(s.steady_rad * kDegPerRad)
           << ", steady_mm: " << num(s.steady_rad * kDegPerRad * mm) << ", start_delay_s: " << num(s.start_delay_s)
           << ", overshoot_pct: " << num(s.overshoot_pct) << ", settling_time_s: " << num(s.settling_time_s);
      if (kind == Km0PhaseKind::LargeStep)
        body << ", settling_excess_s: " << num(g[2].value);
      body << ", static_error_deg: " << num(s.static_error_rad * kDegPerRad)
           << ", static_error_mm: " << num(s.static_error_rad * kDegPerRad * mm)
           << ", peak_speed_radps: " << num(s.peak_speed_radps)
           << ", setpoint_speed_limited: " << (s.setpoint_limited ? "true" : "false") << ",\n"
           << "     verdicts: " << verdictMap(g) << ", verdict: " << km0VerdictName(worst(g)) << "}\n";
    }
    if (!any)
      body << "  []\n";
  };
  stepsSection(Km0PhaseKind::SmallStep, "small_steps");
  stepsSection(Km0PhaseKind::LargeStep, "large_steps");

  body << "ramps:\n";
  if (results.ramps.empty())
    body << "  []\n";
  for (const Km0RampMetrics& r : results.ramps)
  {
    const RampDerived d = derive(r, b);
    const std::vector<Graded> g = gradeRamp(r, d, config.thresholds);
    for (const Graded& x : g)
      ++counts[static_cast<int>(x.verdict)];
    const double fe_deg = r.following_error_rad * kDegPerRad;
    body << "  - {t_s: " << num(r.begin_time_s) << ", command_speed_radps: " << num(r.command_speed_radps)
         << ", amplitude_deg: " << num((r.command_to_rad - r.command_from_rad) * kDegPerRad)
         << ", steady_speed_radps: " << num(r.steady_speed_radps) << ", speed_error_pct: " << num(d.speed_error_pct)
         << ", following_error_deg: " << num(fe_deg) << ", following_error_mm: " << num(fe_deg * mm)
         << ", lag_s: " << num(d.lag_s) << ", speed_settling_time_s: " << num(r.speed_settling_time_s)
         << ", steady_current_a: " << num(r.steady_current_a) << ", friction_torque_nm: " << num(r.friction_torque_nm)
         << ", baseline_friction_nm: " << num(d.baseline_nm) << ", friction_excess_pct: " << num(d.friction_excess_pct)
         << ",\n     verdicts: " << verdictMap(g) << ", verdict: " << km0VerdictName(worst(g)) << "}\n";
  }

  const Km0FrictionFit& f = results.friction_fit;
  body << "friction_fit:  # least squares of Kc*i = B*w + Tp + Tc*sgn(w) over the ramps\n"
       << "  valid: " << (f.valid ? "true" : "false") << "\n  viscous_nms: " << num(f.viscous_nms)
       << "\n  offset_torque_nm: " << num(f.offset_torque_nm) << "\n  coulomb_torque_nm: " << num(f.coulomb_torque_nm)
       << "\n  rms_residual_nm: " << num(f.rms_residual_nm) << "\n";

  const Km0Verdict overall =
      counts[2] > 0 ? Km0Verdict::Intervene : (counts[1] > 0 ? Km0Verdict::Watch : Km0Verdict::Ok);
  y << "# KM0 maintenance protocol (THESIS 2.4), one axis. Angles are mechanical; mm at the plane\n"
    << "# near the field centre (metric.plane_mm_per_deg). Verdicts: value <= watch: ok, <= intervene: watch,\n"
    << "# above (or not measurable): intervene; thresholds in config/km0.yaml.\n"
    << "axis: " << info.name << "\nmodel: " << info.model << "\nperiod_s: " << num(period_s)
    << "\nverdict: " << km0VerdictName(overall) << "\nverdict_counts: {ok: " << counts[0] << ", watch: " << counts[1]
    << ", intervene: " << counts[2] << "}\n"
    << "following_error_grows_with_speed: " << (followingErrorGrows(results.ramps) ? "true" : "false") << "\n"
    << "torque_constant_nm_per_a: " << num(info.torque_constant_nm_per_a) << "\n"
    << "axis_friction: {viscous_nms: " << num(info.viscous_nms) << ", offset_torque_nm: " << num(info.offset_torque_nm)
    << ", coulomb_torque_nm: " << num(info.coulomb_torque_nm) << "}\n"
    << "baseline_friction: {from_servo: " << (b.from_servo ? "true" : "false")
    << ", viscous_nms: " << num(b.viscous_nms) << ", offset_torque_nm: " << num(b.offset_torque_nm)
    << ", coulomb_torque_nm: " << num(b.coulomb_torque_nm) << ", reference_floor_nm: " << num(b.reference_floor_nm)
    << "}\n"
    << "signal: {max_speed_radps: " << num(config.signal.max_speed_radps)
    << ", fir_t1_s: " << num(config.signal.fir_t1_s) << ", fir_t2_s: " << num(config.signal.fir_t2_s)
    << ", joint_lower_rad: " << num(config.signal.joint_lower_rad)
    << ", joint_upper_rad: " << num(config.signal.joint_upper_rad) << "}\n"
    << "metric: {start_threshold_deg: " << num(config.metric.start_threshold_deg)
    << ", settling_band: " << num(config.metric.settling_band) << ", plane_mm_per_deg: " << num(mm) << "}\n"
    << body.str();
  if (!files.empty())
  {
    y << "files:\n";
    for (const std::string& file : files)
      y << "  - " << file << "\n";
  }
  return y.str();
}

void writeKm0Csv(const Km0Signal& signal, const Km0Response& response, const Km0Results& results,
                 const Km0Config& config, const Km0AxisInfo& info, const std::string& out_dir)
{
  const fs::path dir(out_dir);
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec)
    throw InputError(out_dir + ": cannot create (" + ec.message() + ")");

  // Phase index per sample (−1 outside the phases).
  std::vector<int> phase_of(signal.position_rad.size(), -1);
  for (std::size_t p = 0; p < signal.phases.size(); ++p)
    for (std::size_t k = signal.phases[p].begin; k < signal.phases[p].end && k < phase_of.size(); ++k)
      phase_of[k] = static_cast<int>(p);
  {
    std::ofstream out(dir / "km0_signal.csv", std::ios::binary);
    out << "t_s,target_rad,setpoint_rad,setpoint_velocity_radps,setpoint_acceleration_radps2,position_rad,"
           "velocity_radps,current_a,following_error_rad,phase\n";
    char line[512];
    for (std::size_t k = 0; k < signal.position_rad.size(); ++k)
    {
      std::snprintf(line, sizeof line, "%.8g,%.12g,%.12g,%.9g,%.9g,%.12g,%.9g,%.9g,%.9g,%d\n",
                    static_cast<double>(k) * signal.period_s, signal.target_rad[k], signal.position_rad[k],
                    signal.velocity_radps[k], signal.acceleration_radps2[k], response.position_rad[k],
                    response.velocity_radps[k], response.current_a[k],
                    signal.position_rad[k] - response.position_rad[k], phase_of[k]);
      out << line;
    }
    if (!out.good())
      throw InputError((dir / "km0_signal.csv").string() + ": cannot write");
  }
  {
    std::ostringstream out;
    out << "kind,t_s,from_rad,to_rad,steady_rad,start_delay_s,overshoot_pct,settling_time_s,static_error_rad,"
           "peak_speed_radps,setpoint_limited,verdict\n";
    for (const Km0StepMetrics& s : results.steps)
    {
      out << km0PhaseName(s.kind) << "," << num(s.begin_time_s, false) << "," << num(s.command_from_rad, false) << ","
          << num(s.command_to_rad, false) << "," << num(s.steady_rad, false) << "," << num(s.start_delay_s, false)
          << "," << num(s.overshoot_pct, false) << "," << num(s.settling_time_s, false) << ","
          << num(s.static_error_rad, false) << "," << num(s.peak_speed_radps, false) << ","
          << (s.setpoint_limited ? 1 : 0) << ","
          << km0VerdictName(worst(gradeStep(s, config.thresholds, config.signal.max_speed_radps))) << "\n";
    }
    writeTextFile(dir / "km0_steps.csv", out.str());
  }
  {
    const Km0FrictionBaseline b = km0Baseline(config, info);
    std::ostringstream out;
    out << "t_s,command_speed_radps,from_rad,to_rad,ramp_end_time_s,steady_speed_radps,following_error_rad,"
           "lag_s,speed_settling_time_s,steady_current_a,friction_torque_nm,baseline_friction_nm,"
           "friction_excess_pct,verdict\n";
    for (const Km0RampMetrics& r : results.ramps)
    {
      const RampDerived d = derive(r, b);
      out << num(r.begin_time_s, false) << "," << num(r.command_speed_radps, false) << ","
          << num(r.command_from_rad, false) << "," << num(r.command_to_rad, false) << ","
          << num(r.ramp_end_time_s, false) << "," << num(r.steady_speed_radps, false) << ","
          << num(r.following_error_rad, false) << "," << num(d.lag_s, false) << ","
          << num(r.speed_settling_time_s, false) << "," << num(r.steady_current_a, false) << ","
          << num(r.friction_torque_nm, false) << "," << num(d.baseline_nm, false) << ","
          << num(d.friction_excess_pct, false) << "," << km0VerdictName(worst(gradeRamp(r, d, config.thresholds)))
          << "\n";
    }
    writeTextFile(dir / "km0_ramps.csv", out.str());
  }
}

std::string km0Report(const ServoConfig& servo, int axis, double period_s, const Km0Config& config,
                      const std::string& out_dir, const PlotHook& plots)
{
  if (axis != 0 && axis != 1)
    throw ConfigError("km0 axis must be 0 (x) or 1 (y) (got " + std::to_string(axis) + ")");
  servo.validate();
  config.validate();
  const Km0Signal signal = makeKm0Signal(config.signal, period_s);
  std::unique_ptr<AxisModel> model = makeAxisModel(servo, axis, period_s);
  const Km0Response response = runKm0(*model, signal);
  const Km0AxisInfo info = km0AxisInfo(servo, axis);
  const Km0Results results = measureKm0(signal, response, config.metric, info.torque_constant_nm_per_a);

  writeKm0Csv(signal, response, results, config, info, out_dir);
  std::vector<std::string> files = {"km0_report.yaml", "km0_signal.csv", "km0_steps.csv", "km0_ramps.csv"};
  const fs::path dir(out_dir);
  // The plots read km0_report.yaml: write it first, then again with the list of files.
  writeTextFile(dir / "km0_report.yaml", km0ReportYaml(results, config, info, period_s, files));
  if (plots)
  {
    plots(dir.string());
    for (const char* png :
         {"km0_signal.png", "km0_ramps.png", "km0_steps.png", "km0_friction.png", "km0_following_error.png"})
    {
      if (fs::exists(dir / png))
        files.push_back(png);
    }
  }
  const std::string yaml = km0ReportYaml(results, config, info, period_s, files);
  writeTextFile(dir / "km0_report.yaml", yaml);
  return yaml;
}
}  // namespace scanhead
