/// \file km0_config.cpp
#include "scanhead/servo/km0/km0_config.hpp"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <fstream>
#include <sstream>

#include "scanhead/common/config_check.hpp"
#include "scanhead/common/errors.hpp"
#include "scanhead/common/number_text.hpp"
#include "scanhead/common/yaml_document.hpp"

namespace scanhead
{
namespace
{
void requireList(const std::vector<double>& values, const std::string& field, bool allow_empty, bool positive)
{
  if (!allow_empty && values.empty())
    throw ConfigError(field + " must not be empty");
  for (double v : values)
  {
    if (positive)
      requireSetting(v > 0.0, field, "> 0 for every entry", v);
    else
      requireSetting(v != 0.0 && std::isfinite(v), field, "!= 0 for every entry", v);
  }
}

void requireLimit(const Km0Limit& limit, const std::string& field)
{
  requireSetting(limit.watch >= 0.0, field + ".watch", ">= 0", limit.watch);
  requireSetting(limit.intervene >= limit.watch, field + ".intervene", ">= watch", limit.intervene);
}

/// Calls f(name, limit) for every threshold: the one list used to read and check them.
template <class T, class F>
void visitLimits(T& t, F&& f)
{
  f("small_start_delay_s", t.small_start_delay_s);
  f("small_overshoot_pct", t.small_overshoot_pct);
  f("small_settling_time_s", t.small_settling_time_s);
  f("small_static_error_deg", t.small_static_error_deg);
  f("large_start_delay_s", t.large_start_delay_s);
  f("large_overshoot_pct", t.large_overshoot_pct);
  f("large_settling_excess_s", t.large_settling_excess_s);
  f("large_static_error_deg", t.large_static_error_deg);
  f("ramp_lag_s", t.ramp_lag_s);
  f("ramp_speed_error_pct", t.ramp_speed_error_pct);
  f("ramp_speed_settling_s", t.ramp_speed_settling_s);
  f("ramp_friction_excess_pct", t.ramp_friction_excess_pct);
}

std::string where(const YAML::Node& node, const std::string& source, const std::string& key)
{
  std::ostringstream s;
  s << source << ":" << node.Mark().line + 1 << ": km0." << key;
  return s.str();
}

double readNumber(const YAML::Node& node, const std::string& source, const std::string& key)
{
  if (!node.IsScalar())
    throw InputError(where(node, source, key) + ": expected a number");
  double value = 0.0;
  const NumberText result = parseNumber(node.Scalar(), value);
  if (result != NumberText::Ok)
    throw InputError(where(node, source, key) + ": '" + node.Scalar() + "' is not a finite number");
  return value;
}

/// Visits the entries of a map node, rejecting unknown keys.
class Section
{
public:
  Section(const YAML::Node& node, const std::string& source, const std::string& name)
    : node_(node)
    , source_(source)
    , name_(name)
  {
    if (node_ && !node_.IsMap())
      throw InputError(where(node_, source_, name_) + ": expected a map");
  }
  template <class F>
  void each(F&& f) const
  {
    if (!node_)
      return;
    for (const auto& entry : node_)
    {
      const std::string key = entry.first.as<std::string>();
      if (!f(key, entry.second))
        throw InputError(where(entry.first, source_, name_ + "." + key) + ": unknown key");
    }
  }
  std::string key(const std::string& k) const { return name_ + "." + k; }

private:
  YAML::Node node_;
  std::string source_;
  std::string name_;
};
}  // namespace

void Km0SignalConfig::validate() const
{
  requireSetting(joint_upper_rad > joint_lower_rad, "km0.signal.joint_upper_rad", "> joint_lower_rad", joint_upper_rad);
  requireSetting(std::isfinite(joint_lower_rad), "km0.signal.joint_lower_rad", "finite", joint_lower_rad);
  requireSetting(range_margin_deg >= 0.0, "km0.signal.range_margin_deg", ">= 0", range_margin_deg);
  requireSetting(max_speed_radps > 0.0, "km0.signal.max_speed_radps", "> 0", max_speed_radps);
  requireSetting(fir_t1_s >= 0.0, "km0.signal.fir_t1_s", ">= 0", fir_t1_s);
  requireSetting(fir_t2_s >= 0.0, "km0.signal.fir_t2_s", ">= 0", fir_t2_s);
  requireList(small_steps_deg, "km0.signal.small_steps_deg", true, false);
  requireList(large_steps_deg, "km0.signal.large_steps_deg", true, false);
  requireList(ramp_speeds_radps, "km0.signal.ramp_speeds_radps", true, true);
  requireSetting(ramp_duration_s > 0.0, "km0.signal.ramp_duration_s", "> 0", ramp_duration_s);
  requireSetting(min_ramp_duration_s > fir_t1_s, "km0.signal.min_ramp_duration_s", "> fir_t1_s", min_ramp_duration_s);
  requireSetting(ramp_duration_s >= min_ramp_duration_s, "km0.signal.ramp_duration_s", ">= min_ramp_duration_s",
                 ramp_duration_s);
  requireSetting(step_hold_s > 0.0, "km0.signal.step_hold_s", "> 0", step_hold_s);
  requireSetting(ramp_hold_s > 0.0, "km0.signal.ramp_hold_s", "> 0", ramp_hold_s);
  requireSetting(start_hold_s >= 0.0, "km0.signal.start_hold_s", ">= 0", start_hold_s);
}

void Km0MetricConfig::validate() const
{
  requireSetting(start_threshold_deg > 0.0, "km0.metric.start_threshold_deg", "> 0", start_threshold_deg);
  requireSetting(settling_band > 0.0 && settling_band < 1.0, "km0.metric.settling_band", "in (0, 1)", settling_band);
  requireSetting(plane_mm_per_deg > 0.0, "km0.metric.plane_mm_per_deg", "> 0", plane_mm_per_deg);
}

void Km0Thresholds::validate() const
{
  visitLimits(*this,
              [](const char* name, const Km0Limit& l) { requireLimit(l, std::string("km0.thresholds.") + name); });
}

void Km0FrictionBaseline::validate() const
{
  requireSetting(viscous_nms >= 0.0, "km0.baseline.viscous_nms", ">= 0", viscous_nms);
  requireSetting(std::isfinite(offset_torque_nm), "km0.baseline.offset_torque_nm", "finite", offset_torque_nm);
  requireSetting(coulomb_torque_nm >= 0.0, "km0.baseline.coulomb_torque_nm", ">= 0", coulomb_torque_nm);
  requireSetting(reference_floor_nm > 0.0, "km0.baseline.reference_floor_nm", "> 0", reference_floor_nm);
}

void Km0Config::validate() const
{
  signal.validate();
  metric.validate();
  thresholds.validate();
  baseline.validate();
}

Km0Config km0ConfigFromYaml(const std::string& yaml_text, const std::string& source)
{
  const YAML::Node root = parseYamlDocument(yaml_text, source, yamlSettingsLimits("a KM0 config"));
  Km0Config c;
  if (!root || root.IsNull())
    return c;
  if (!root.IsMap())
    throw InputError(source + ": the KM0 config must be a map");

  auto num = [&](const YAML::Node& n, const std::string& key) { return readNumber(n, source, key); };
  auto list = [&](const YAML::Node& n, const std::string& key) {
    if (!n.IsSequence())
      throw InputError(where(n, source, key) + ": expected a list of numbers");
    std::vector<double> out;
    for (const auto& item : n)
      out.push_back(num(item, key));
    return out;
  };

  Section top(root, source, "");
  top.each([&](const std::string& name, const YAML::Node& node) {
    if (name == "signal")
    {
      Section sec(node, source, "signal");
      Km0SignalConfig& s = c.signal;
      sec.each([&](const std::string& k, const YAML::Node& v) {
        const std::string key = sec.key(k);
        if (k == "joint_lower_rad")
          s.joint_lower_rad = num(v, key);
        else if (k == "joint_upper_rad")
          s.joint_upper_rad = num(v, key);
        else if (k == "range_margin_deg")
          s.range_margin_deg = num(v, key);
        else if (k == "max_speed_radps")
          s.max_speed_radps = num(v, key);
        else if (k == "fir_t1_s")
          s.fir_t1_s = num(v, key);
        else if (k == "fir_t2_s")
          s.fir_t2_s = num(v, key);
        else if (k == "small_steps_deg")
          s.small_steps_deg = list(v, key);
        else if (k == "large_steps_deg")
          s.large_steps_deg = list(v, key);
        else if (k == "ramp_speeds_radps")
          s.ramp_speeds_radps = list(v, key);
        else if (k == "ramp_duration_s")
          s.ramp_duration_s = num(v, key);
        else if (k == "min_ramp_duration_s")
          s.min_ramp_duration_s = num(v, key);
        else if (k == "step_hold_s")
          s.step_hold_s = num(v, key);
        else if (k == "ramp_hold_s")
          s.ramp_hold_s = num(v, key);
        else if (k == "start_hold_s")
          s.start_hold_s = num(v, key);
        else
          return false;
        return true;
      });
      return true;
    }
    if (name == "metric")
    {
      Section sec(node, source, "metric");
      sec.each([&](const std::string& k, const YAML::Node& v) {
        const std::string key = sec.key(k);
        if (k == "start_threshold_deg")
          c.metric.start_threshold_deg = num(v, key);
        else if (k == "settling_band")
          c.metric.settling_band = num(v, key);
        else if (k == "plane_mm_per_deg")
          c.metric.plane_mm_per_deg = num(v, key);
        else
          return false;
        return true;
      });
      return true;
    }
    if (name == "thresholds")
    {
      Section sec(node, source, "thresholds");
      sec.each([&](const std::string& k, const YAML::Node& v) {
        bool known = false;
        visitLimits(c.thresholds, [&](const char* limit_name, Km0Limit& limit) {
          if (k != limit_name)
            return;
          known = true;
          Section pair(v, source, sec.key(k));
          pair.each([&](const std::string& which, const YAML::Node& value) {
            if (which == "watch")
              limit.watch = num(value, pair.key(which));
            else if (which == "intervene")
              limit.intervene = num(value, pair.key(which));
            else
              return false;
            return true;
          });
        });
        return known;
      });
      return true;
    }
    if (name == "baseline")
    {
      Section sec(node, source, "baseline");
      sec.each([&](const std::string& k, const YAML::Node& v) {
        const std::string key = sec.key(k);
        if (k == "from_servo")
        {
          if (!v.IsScalar() || (v.Scalar() != "true" && v.Scalar() != "false"))
            throw InputError(where(v, source, key) + ": expected true or false");
          c.baseline.from_servo = v.Scalar() == "true";
        }
        else if (k == "viscous_nms")
          c.baseline.viscous_nms = num(v, key);
        else if (k == "offset_torque_nm")
          c.baseline.offset_torque_nm = num(v, key);
        else if (k == "coulomb_torque_nm")
          c.baseline.coulomb_torque_nm = num(v, key);
        else if (k == "reference_floor_nm")
          c.baseline.reference_floor_nm = num(v, key);
        else
          return false;
        return true;
      });
      return true;
    }
    return false;
  });
  c.validate();
  return c;
}

Km0Config loadKm0Config(const std::string& path)
{
  if (path.empty())
  {
    Km0Config c;
    c.validate();
    return c;
  }
  return km0ConfigFromYaml(readYamlText(path, yamlSettingsLimits("a KM0 config", "the KM0 config")), path);
}
}  // namespace scanhead
