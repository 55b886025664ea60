#include "scanhead/chain/config_io.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
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
/// Calls f(key, member) for every setting: the single list of keys, used to read, write and check.
template <class Config, class F>
void visitSettings(Config& c, F&& f)
{
  f("cam.layer", c.cam.layer);
  f("cam.units", c.cam.units);
  f("cam.mark_speed_mps", c.cam.mark_speed_mps);
  f("cam.jump_speed_mps", c.cam.jump_speed_mps);
  f("cam.mark_power_w", c.cam.mark_power_w);
  f("cam.shape_file", c.cam.shape_file);
  f("cam.segment_power", c.cam.segment_power);
  f("cam.offset_m", c.cam.offset_m);
  f("cam.rotation_deg", c.cam.rotation_deg);
  f("cam.centre", c.cam.centre);
  f("stream.chunk_samples", c.stream.chunk_samples);
  f("stream.window_chunks", c.stream.window_chunks);
  f("stream.threads", c.stream.threads);
  f("nc.period_s", c.nc.period_s);
  f("nc.fir_t1_s", c.nc.fir_t1_s);
  f("nc.fir_t2_s", c.nc.fir_t2_s);
  f("nc.max_joint_speed_radps", c.nc.max_joint_speed_radps);
  f("nc.implicit_jump_speed_mps", c.nc.implicit_jump_speed_mps);
  f("nc.tail_s", c.nc.tail_s);
  f("nc.debug", c.nc.debug);
  f("nc.igt.mode", c.nc.igt.mode);
  f("nc.igt.table_file", c.nc.igt.table_file);
  f("nc.igt.table_nodes", c.nc.igt.table_nodes);
  f("nc.igt.table_interpolation", c.nc.igt.table_interpolation);
  f("nc.filter_mode", c.nc.filter_mode);
  f("nc.max_joint_accel_radps2", c.nc.max_joint_accel_radps2);
  f("nc.max_joint_jerk_radps3", c.nc.max_joint_jerk_radps3);
  f("nc.cap_speeds", c.nc.cap_speeds);
  f("nc.mark_delay_s", c.nc.mark_delay_s);
  f("nc.jump_delay_s", c.nc.jump_delay_s);
  f("nc.polygon_delay_s", c.nc.polygon_delay_s);
  f("nc.polygon_delay_mode", c.nc.polygon_delay_mode);
  f("nc.skywriting.enabled", c.nc.skywriting.enabled);
  f("nc.skywriting.run_in_m", c.nc.skywriting.run_in_m);
  f("nc.skywriting.run_in_s", c.nc.skywriting.run_in_s);
  f("nc.skywriting.run_out_m", c.nc.skywriting.run_out_m);
  f("nc.skywriting.run_out_s", c.nc.skywriting.run_out_s);
  f("nc.skywriting.min_angle_deg", c.nc.skywriting.min_angle_deg);
  f("nc.power_mode", c.nc.power_mode);
  f("nc.power_floor", c.nc.power_floor);
  f("nc.quantisation_bits", c.nc.quantisation_bits);
  f("recipe.preset", c.recipe.preset);
  f("recipe.contour_speed_mps", c.recipe.contour_speed_mps);
  f("recipe.contour_power_w", c.recipe.contour_power_w);
  f("recipe.hatch_speed_mps", c.recipe.hatch_speed_mps);
  f("recipe.hatch_power_w", c.recipe.hatch_power_w);
  f("recipe.jump_speed_mps", c.recipe.jump_speed_mps);
  f("recipe.contour_jump_speed_mps", c.recipe.contour_jump_speed_mps);
  f("recipe.laser_on_delay_s", c.recipe.laser_on_delay_s);
  f("recipe.laser_off_delay_s", c.recipe.laser_off_delay_s);
  f("servo.model", c.servo.model);
  f("servo.x.bandwidth_hz", c.servo.x.bandwidth_hz);
  f("servo.x.damping", c.servo.x.damping);
  f("servo.x.pole_ratio", c.servo.x.pole_ratio);
  f("servo.x.plant.resistance_ohm", c.servo.x.plant.resistance_ohm);
  f("servo.x.plant.inductance_h", c.servo.x.plant.inductance_h);
  f("servo.x.plant.torque_constant_nm_per_a", c.servo.x.plant.torque_constant_nm_per_a);
  f("servo.x.plant.inertia_kgm2", c.servo.x.plant.inertia_kgm2);
  f("servo.x.plant.viscous_nms", c.servo.x.plant.viscous_nms);
  f("servo.x.plant.offset_torque_nm", c.servo.x.plant.offset_torque_nm);
  f("servo.x.plant.coulomb_torque_nm", c.servo.x.plant.coulomb_torque_nm);
  f("servo.x.plant.mode_gain", c.servo.x.plant.mode_gain);
  f("servo.x.plant.mode_damping", c.servo.x.plant.mode_damping);
  f("servo.x.plant.mode_frequency_hz", c.servo.x.plant.mode_frequency_hz);
  f("servo.x.plant.supply_voltage_v", c.servo.x.plant.supply_voltage_v);
  f("servo.x.gains.kii", c.servo.x.gains.kii);
  f("servo.x.gains.tii_s", c.servo.x.gains.tii_s);
  f("servo.x.gains.kiw", c.servo.x.gains.kiw);
  f("servo.x.gains.tiw_s", c.servo.x.gains.tiw_s);
  f("servo.x.gains.ktheta", c.servo.x.gains.ktheta);
  f("servo.x.gains.tdtheta_s", c.servo.x.gains.tdtheta_s);
  f("servo.x.gains.tauf_s", c.servo.x.gains.tauf_s);
  f("servo.x.gains.k1", c.servo.x.gains.k1);
  f("servo.x.gains.k2", c.servo.x.gains.k2);
  f("servo.y.bandwidth_hz", c.servo.y.bandwidth_hz);
  f("servo.y.damping", c.servo.y.damping);
  f("servo.y.pole_ratio", c.servo.y.pole_ratio);
  f("servo.y.plant.resistance_ohm", c.servo.y.plant.resistance_ohm);
  f("servo.y.plant.inductance_h", c.servo.y.plant.inductance_h);
  f("servo.y.plant.torque_constant_nm_per_a", c.servo.y.plant.torque_constant_nm_per_a);
  f("servo.y.plant.inertia_kgm2", c.servo.y.plant.inertia_kgm2);
  f("servo.y.plant.viscous_nms", c.servo.y.plant.viscous_nms);
  f("servo.y.plant.offset_torque_nm", c.servo.y.plant.offset_torque_nm);
  f("servo.y.plant.coulomb_torque_nm", c.servo.y.plant.coulomb_torque_nm);
  f("servo.y.plant.mode_gain", c.servo.y.plant.mode_gain);
  f("servo.y.plant.mode_damping", c.servo.y.plant.mode_damping);
  f("servo.y.plant.mode_frequency_hz", c.servo.y.plant.mode_frequency_hz);
  f("servo.y.plant.supply_voltage_v", c.servo.y.plant.supply_voltage_v);
  f("servo.y.gains.kii", c.servo.y.gains.kii);
  f("servo.y.gains.tii_s", c.servo.y.gains.tii_s);
  f("servo.y.gains.kiw", c.servo.y.gains.kiw);
  f("servo.y.gains.tiw_s", c.servo.y.gains.tiw_s);
  f("servo.y.gains.ktheta", c.servo.y.gains.ktheta);
  f("servo.y.gains.tdtheta_s", c.servo.y.gains.tdtheta_s);
  f("servo.y.gains.tauf_s", c.servo.y.gains.tauf_s);
  f("servo.y.gains.k1", c.servo.y.gains.k1);
  f("servo.y.gains.k2", c.servo.y.gains.k2);
  f("servo.kc_over_jeq", c.servo.kc_over_jeq);
  f("servo.controller_rate_hz", c.servo.controller_rate_hz);
  f("servo.feedforward_derivatives", c.servo.feedforward_derivatives);
  f("servo.voltage_feedforward", c.servo.voltage_feedforward);
  f("servo.position_controller", c.servo.position_controller);
  f("servo.hinf.w1.g0", c.servo.hinf.w1.g0);
  f("servo.hinf.w1.ginf", c.servo.hinf.w1.ginf);
  f("servo.hinf.w1.w0_rad_s", c.servo.hinf.w1.w0_rad_s);
  f("servo.hinf.w2.g0", c.servo.hinf.w2.g0);
  f("servo.hinf.w2.ginf", c.servo.hinf.w2.ginf);
  f("servo.hinf.w2.w0_rad_s", c.servo.hinf.w2.w0_rad_s);
  f("servo.hinf.w3.g0", c.servo.hinf.w3.g0);
  f("servo.hinf.w3.ginf", c.servo.hinf.w3.ginf);
  f("servo.hinf.w3.w0_rad_s", c.servo.hinf.w3.w0_rad_s);
  f("servo.hinf.gamma_tolerance", c.servo.hinf.gamma_tolerance);
  f("servo.hinf.reduced_order", c.servo.hinf.reduced_order);
  f("optics.urdf_path", c.optics.urdf_path);
  f("optics.defects", c.optics.defects);
  f("optics.window_thickness_m", c.optics.window_thickness_m);
  f("optics.n_gas", c.optics.n_gas);
  f("optics.n_window", c.optics.n_window);
  f("optics.field_half_width_m", c.optics.field_half_width_m);
  f("optics.newton_tolerance_m", c.optics.newton_tolerance_m);
  f("optics.newton_max_iterations", c.optics.newton_max_iterations);
  f("energy.spot_diameter_m", c.energy.spot_diameter_m);
  f("energy.pixel_m", c.energy.pixel_m);
  f("energy.method", c.energy.method);
  f("energy.stroke_tolerance_m", c.energy.stroke_tolerance_m);
  f("energy.max_substep_radii", c.energy.max_substep_radii);
  f("energy.truncation_radii", c.energy.truncation_radii);
  f("energy.map_margin_m", c.energy.map_margin_m);
  f("energy.corner_min_angle_deg", c.energy.corner_min_angle_deg);
  f("energy.laser_path_tolerance_m", c.energy.laser_path_tolerance_m);
  f("energy.track_exclude_ends_m", c.energy.track_exclude_ends_m);
  f("energy.track_max_samples", c.energy.track_max_samples);
  f("energy.tile_cache_bytes", c.energy.tile_cache_bytes);
  f("energy.oblique_incidence", c.energy.oblique_incidence);
  f("energy.defocus_mode", c.energy.defocus_mode);
  f("energy.defocus_m", c.energy.defocus_m);
  f("energy.focus_distance_m", c.energy.focus_distance_m);
  f("energy.wavelength_m", c.energy.wavelength_m);
  f("energy.beam_quality_m2", c.energy.beam_quality_m2);
  f("energy.crop_parts", c.energy.crop_parts);
  f("energy.crop_regions", c.energy.crop_regions);
  f("energy.contour_max_samples", c.energy.contour_max_samples);
  f("energy.contour_lag_s", c.energy.contour_lag_s);
  f("energy.same_instant_window_s", c.energy.same_instant_window_s);
  f("energy.spill_dir", c.energy.spill_dir);
  f("thermal.enabled", c.thermal.enabled);
  f("thermal.start_s", c.thermal.start_s);
  f("thermal.duration_s", c.thermal.duration_s);
  f("thermal.density_solid_kg_m3", c.thermal.model.density_solid_kg_m3);
  f("thermal.density_powder_kg_m3", c.thermal.model.density_powder_kg_m3);
  f("thermal.heat_capacity_solid_j_kg_k", c.thermal.model.heat_capacity_solid_j_kg_k);
  f("thermal.heat_capacity_powder_j_kg_k", c.thermal.model.heat_capacity_powder_j_kg_k);
  f("thermal.conductivity_solid_w_m_k", c.thermal.model.conductivity_solid_w_m_k);
  f("thermal.conductivity_powder_w_m_k", c.thermal.model.conductivity_powder_w_m_k);
  f("thermal.loss_depth_m", c.thermal.model.loss_depth_m);
  f("thermal.layer_thickness_m", c.thermal.model.layer_thickness_m);
  f("thermal.melt_temperature_k", c.thermal.model.melt_temperature_k);
  f("thermal.ambient_temperature_k", c.thermal.model.ambient_temperature_k);
  f("thermal.phase_switch", c.thermal.model.phase_switch);
  f("thermal.absorptivity", c.thermal.model.absorptivity);
  f("thermal.spot_diameter_m", c.thermal.model.spot_diameter_m);
  f("thermal.source_truncation_radii", c.thermal.model.source_truncation_radii);
  f("thermal.max_substep_radii", c.thermal.model.max_substep_radii);
  f("thermal.cell_m", c.thermal.model.cell_m);
  f("thermal.window_m", c.thermal.model.window_m);
  f("thermal.recentre_margin_m", c.thermal.model.recentre_margin_m);
  f("thermal.step_samples", c.thermal.model.step_samples);
  f("thermal.face_conductivity", c.thermal.model.face_conductivity);
  f("thermal.active_threshold_k", c.thermal.model.active_threshold_k);
  f("thermal.settle_time_s", c.thermal.model.settle_time_s);
  f("limits.max_machine_time_s", c.limits.max_machine_time_s);
  f("limits.max_samples", c.limits.max_samples);
  f("limits.max_memory_fraction", c.limits.max_memory_fraction);
  f("limits.max_memory_bytes", c.limits.max_memory_bytes);
}

std::string origin(const std::string& key, const ConfigValue& v)
{
  return key + " (" + v.where + ")";
}

void parseValue(const std::string& key, const ConfigValue& v, double& out)
{
  switch (parseNumber(v.text, out))
  {
    case NumberText::Ok:
      return;
    case NumberText::NotFinite:
      throw ConfigError(origin(key, v) + ": '" + v.text + "' is not a finite number");
    case NumberText::NotNumber:
      throw ConfigError(origin(key, v) + ": '" + v.text + "' is not a number");
  }
}

void parseValue(const std::string& key, const ConfigValue& v, std::size_t& out)
{
  double value = 0.0;
  parseValue(key, v, value);
  if (value < 0.0 || value != std::floor(value) || value > 1e15)
    throw ConfigError(origin(key, v) + ": '" + v.text + "' is not a non-negative integer");
  out = static_cast<std::size_t>(value);
}

void parseValue(const std::string& key, const ConfigValue& v, int& out)
{
  double value = 0.0;
  parseValue(key, v, value);
  if (value != std::floor(value) || std::fabs(value) > 1e9)
    throw ConfigError(origin(key, v) + ": '" + v.text + "' is not an integer");
  out = static_cast<int>(value);
}

void parseValue(const std::string& key, const ConfigValue& v, bool& out)
{
  if (v.text == "true" || v.text == "True" || v.text == "1")
    out = true;
  else if (v.text == "false" || v.text == "False" || v.text == "0")
    out = false;
  else
    throw ConfigError(origin(key, v) + ": '" + v.text + "' is not true or false");
}

void parseValue(const std::string&, const ConfigValue& v, std::string& out)
{
  out = v.text;
}

/// "[x, y]" (a YAML list, or the same text after --set), also "x, y" or "x y".
void parseValue(const std::string& key, const ConfigValue& v, std::array<double, 2>& out)
{
  std::string text = v.text;
  for (char& c : text)
    if (c == '[' || c == ']' || c == ',')
      c = ' ';
  std::istringstream words(text);
  std::vector<std::string> parts;
  for (std::string word; words >> word;)
    parts.push_back(word);
  if (parts.size() != 2)
    throw ConfigError(origin(key, v) + ": '" + v.text + "' is not a pair [x, y]");
  for (std::size_t i = 0; i < 2; ++i)
    parseValue(key + "[" + std::to_string(i) + "]", ConfigValue{parts[i], v.where}, out[i]);
}

std::string formatValue(double v)
{
  return fullPrecisionText(v);
}
std::string formatValue(std::size_t v)
{
  return std::to_string(v);
}
std::string formatValue(int v)
{
  return std::to_string(v);
}
std::string formatValue(bool v)
{
  return v ? "true" : "false";
}
std::string formatValue(const std::array<double, 2>& v)
{
  return "[" + fullPrecisionText(v[0]) + ", " + fullPrecisionText(v[1]) + "]";
}
std::string formatValue(const std::string& v)
{
  return yamlDoubleQuoted(v);  // escaped (found by fuzz_config: a quote or newline broke the round trip)
}

void flattenNode(const YAML::Node& node, const std::string& prefix, const std::string& source, FlatConfig& out)
{
  const std::string where = source + ":" + std::to_string(node.Mark().line + 1);
  if (node.IsScalar())
  {
    // "nc: {period_s: 1}" and "nc.period_s: 2" are one setting given twice (YAML sees two keys).
    const auto [it, fresh] = out.emplace(prefix, ConfigValue{node.Scalar(), where});
    if (!fresh)
      throw InputError(where + ": " + prefix + " is given twice (first at " + it->second.where + ")");
    return;
  }
  if (node.IsNull())
    return;
  if (node.IsSequence() && std::all_of(node.begin(), node.end(), [](const YAML::Node& n) { return n.IsScalar(); }))
  {
    // A list of numbers (cam.offset_m: [x, y]): kept as its text, parsed by the setting's type.
    std::string text = "[";
    for (std::size_t i = 0; i < node.size(); ++i)
      text += (i ? ", " : "") + node[i].Scalar();
    const auto [it, fresh] = out.emplace(prefix, ConfigValue{text + "]", where});
    if (!fresh)
      throw InputError(where + ": " + prefix + " is given twice (first at " + it->second.where + ")");
    return;
  }
  if (!node.IsMap())
    throw InputError(where + ": " + (prefix.empty() ? std::string("the file") : prefix) +
                     " must be a map of settings, not a list");
  for (const auto& item : node)
  {
    if (!item.first.IsScalar())  // "? [a, b]: 1" or "~: 1" (found by fuzz_config: escaped as YAML::Exception)
      throw InputError(source + ":" + std::to_string(item.first.Mark().line + 1) + ": " +
                       (prefix.empty() ? std::string("a top-level key") : "a key under " + prefix) + " is not a name");
    const std::string key = item.first.Scalar();
    flattenNode(item.second, prefix.empty() ? key : prefix + "." + key, source, out);
  }
}

std::string joinKeys()
{
  std::string all;
  for (const auto& k : knownConfigKeys())
    all += (all.empty() ? "" : ", ") + k;
  return all;
}
}  // namespace

std::vector<std::string> differingSettings(const std::string& yaml_a, const std::string& yaml_b,
                                           const std::vector<std::string>& sections)
{
  if (yaml_a == yaml_b)
    return {};  // nothing differs, and reading both costs ~2 ms (the energy node asks at every job)
  const FlatConfig a = flattenYaml(yaml_a, "settings a");
  const FlatConfig b = flattenYaml(yaml_b, "settings b");
  auto wanted = [&](const std::string& key) {
    return std::any_of(sections.begin(), sections.end(),
                       [&](const std::string& s) { return key.compare(0, s.size() + 1, s + ".") == 0; });
  };
  auto text = [](const FlatConfig& flat, const std::string& key) {
    const auto it = flat.find(key);
    return it == flat.end() ? std::string("(none)") : it->second.text;
  };
  std::vector<std::string> out;
  for (const std::string& key : knownConfigKeys())
  {
    if (wanted(key) && text(a, key) != text(b, key))
      out.push_back(key + ": " + text(a, key) + " vs " + text(b, key));
  }
  return out;
}

std::vector<std::string> knownConfigKeys()
{
  // Built once: every --set and every unknown key looked the sorted list up (rebuilt and re-sorted
  // each time, the largest cost of reading a config under fuzz_config).
  static const std::vector<std::string> keys = [] {
    std::vector<std::string> list;
    ChainConfig c;
    visitSettings(c, [&](const char* key, auto&) { list.emplace_back(key); });
    std::sort(list.begin(), list.end());
    return list;
  }();
  return keys;
}

FlatConfig flattenYaml(const std::string& yaml_text, const std::string& source)
{
  const YAML::Node root = parseYamlDocument(yaml_text, source, yamlSettingsLimits("a config file"));
  FlatConfig flat;
  flattenNode(root, "", source, flat);
  return flat;
}

void applyOverride(FlatConfig& flat, const std::string& assignment)
{
  const auto eq = assignment.find('=');
  if (eq == std::string::npos || eq == 0)
    throw ConfigError("--set '" + assignment + "': expected section.key=value");
  const std::string key = assignment.substr(0, eq);
  const auto keys = knownConfigKeys();
  if (!std::binary_search(keys.begin(), keys.end(), key))
    throw ConfigError("--set '" + assignment + "': unknown key '" + key + "' (known: " + joinKeys() + ")");
  flat[key] = ConfigValue{assignment.substr(eq + 1), "--set"};
}

ChainConfig chainConfigFromFlat(const FlatConfig& flat)
{
  ChainConfig config;
  std::size_t used = 0;
  visitSettings(config, [&](const char* key, auto& member) {
    const auto it = flat.find(key);
    if (it == flat.end())
      return;
    parseValue(key, it->second, member);
    ++used;
  });
  if (used != flat.size())
  {
    const auto keys = knownConfigKeys();
    for (const auto& [key, value] : flat)
      if (!std::binary_search(keys.begin(), keys.end(), key))
        throw ConfigError(origin(key, value) + ": unknown setting (known: " + joinKeys() + ")");
  }
  config.validate();
  return config;
}

ChainConfig loadChainConfig(const std::string& path, const std::vector<std::string>& overrides)
{
  FlatConfig flat;
  if (!path.empty())
  {
    flat = flattenYaml(readYamlText(path, yamlSettingsLimits("a config file", "the config file")), path);
  }
  for (const auto& assignment : overrides)
    applyOverride(flat, assignment);
  return chainConfigFromFlat(flat);
}

std::string chainConfigToYaml(const ChainConfig& config)
{
  // Settings are visited grouped by section, so one line per key under its section headers.
  std::ostringstream out;
  std::vector<std::string> open;  // section path currently written
  ChainConfig copy = config;
  visitSettings(copy, [&](const char* key, auto& member) {
    std::vector<std::string> parts;
    std::stringstream ss(key);
    for (std::string part; std::getline(ss, part, '.');)
      parts.push_back(part);
    std::size_t common = 0;
    while (common < open.size() && common + 1 < parts.size() && open[common] == parts[common])
      ++common;
    open.resize(common);
    for (std::size_t i = common; i + 1 < parts.size(); ++i)
    {
      out << std::string(2 * i, ' ') << parts[i] << ":\n";
      open.push_back(parts[i]);
    }
    out << std::string(2 * (parts.size() - 1), ' ') << parts.back() << ": " << formatValue(member) << "\n";
  });
  return out.str();
}

void StreamConfig::validate() const
{
  requireSetting(chunk_samples >= 1, "stream.chunk_samples", ">= 1", static_cast<double>(chunk_samples));
  requireSetting(window_chunks >= 1, "stream.window_chunks", ">= 1", static_cast<double>(window_chunks));
  requireSetting(threads == 1 || threads == 2, "stream.threads", "1 or 2", static_cast<double>(threads));
  // Every stage holds a few chunks (~1 kB a sample over the streams and the NC's work arrays):
  // 1e6 samples (10 s at 100 kHz) is already ~1 GB, and larger chunks gain nothing.
  requireSetting(chunk_samples <= 1000000, "stream.chunk_samples", "<= 1000000 (memory grows with it, ~1 kB a sample)",
                 static_cast<double>(chunk_samples));
  requireSetting(window_chunks <= 1000000, "stream.window_chunks", "<= 1000000", static_cast<double>(window_chunks));
}

void LimitsConfig::validate() const
{
  requireSetting(max_machine_time_s > 0.0, "limits.max_machine_time_s", "> 0", max_machine_time_s);
  requireSetting(max_samples >= 1.0, "limits.max_samples", ">= 1", max_samples);
  requireSetting(max_memory_fraction > 0.0 && max_memory_fraction <= 1.0, "limits.max_memory_fraction", "in (0, 1]",
                 max_memory_fraction);
  requireSetting(max_memory_bytes >= 0.0, "limits.max_memory_bytes", ">= 0 (0: the fraction only)", max_memory_bytes);
}

void ChainConfig::validate() const
{
  cam.validate();
  stream.validate();
  nc.validate();
  recipe.validate();
  servo.validate();
  optics.validate();
  energy.validate();
  thermal.validate();
  limits.validate();
}

void ThermalStageConfig::validate() const
{
  requireSetting(std::isfinite(start_s) && start_s >= 0.0, "thermal.start_s", ">= 0", start_s);
  requireSetting(std::isfinite(duration_s), "thermal.duration_s", "finite (<= 0: to the end)", duration_s);
  model.validate();
}
}  // namespace scanhead
