/// \file run_comparison.cpp
#include "scanhead/metrics/run_comparison.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "scanhead/common/errors.hpp"
#include "scanhead/common/number_text.hpp"
#include "scanhead/common/yaml_document.hpp"

namespace scanhead
{
namespace
{
struct Figure
{
  const char* key;
  const char* label;
  const char* unit;
  double scale;
  Better better;
};

// What THESIS Table 3.1 and §2.6.2 compare, then the figures a process engineer adds.
const Figure kFigures[] = {
    {"layer_time_s", "layer time", "s", 1.0, Better::Lower},
    {"fill_rate", "fill rate (hatch)", "%", 100.0, Better::Higher},
    {"contour_error.same_instant.contour.share_under_10um", "contours < 10 um, same instant", "%", 100.0,
     Better::Higher},
    {"contour_error.same_instant.contour.share_under_20um", "contours < 20 um, same instant", "%", 100.0,
     Better::Higher},
    {"contour_error.same_instant.contour.share_under_30um", "contours < 30 um, same instant", "%", 100.0,
     Better::Higher},
    {"contour_error.nearest_path.contour.share_under_10um", "contours < 10 um, nearest path", "%", 100.0,
     Better::Higher},
    {"contour_error.nearest_path.contour.share_under_20um", "contours < 20 um, nearest path", "%", 100.0,
     Better::Higher},
    {"contour_error.nearest_path.contour.share_under_30um", "contours < 30 um, nearest path", "%", 100.0,
     Better::Higher},
    {"contour_error.same_instant.share_under_10um", "marks < 10 um, same instant", "%", 100.0, Better::Higher},
    {"contour_error.same_instant.share_under_30um", "marks < 30 um, same instant", "%", 100.0, Better::Higher},
    {"contour_error.same_instant.hatch.share_under_10um", "hatch < 10 um, same instant", "%", 100.0, Better::Higher},
    {"contour_error.same_instant.jump.share_under_30um", "jumps < 30 um, same instant", "%", 100.0, Better::Higher},
    {"contour_error.same_instant.contour.max_m", "contour error max, same instant", "um", 1e6, Better::Lower},
    {"contour_error.same_instant.contour.p99_m", "contour error p99, same instant", "um", 1e6, Better::Lower},
    {"speed_profile.mean_ratio", "mark speed / programmed (mean)", "%", 100.0, Better::Higher},
    {"speed_profile.share_below_90pct", "mark time below 90 % speed", "%", 100.0, Better::Lower},
    {"angle_error.x.quantiles.p99", "angle error x p99", "urad", 1.0, Better::Lower},
    {"angle_error.y.quantiles.p99", "angle error y p99", "urad", 1.0, Better::Lower},
    {"peak_energy_density_jpm2", "peak energy density", "J/mm^2", 1e-6, Better::None},
    {"track_energy.mean_jpm2", "mean energy along tracks", "J/mm^2", 1e-6, Better::None},
    {"corner_energy.max_peak_to_track_mean", "corner peak / track mean (max)", "x", 1.0, Better::Lower},
    {"laser_off_path_samples", "laser on off the marks", "samples", 1.0, Better::Lower},
    {"dropped_samples", "dropped samples", "samples", 1.0, Better::Lower},
};

/// metrics.yaml up to its corner list: a whole layer has ~1e5 corners (40 MB) that no figure here needs.
YAML::Node load(const std::string& path)
{
  std::ifstream in(path, std::ios::binary);
  if (!in)
    throw InputError(path + ": cannot read (give a results folder or its metrics.yaml)");
  const YamlLimits limits = yamlMetricsLimits();
  std::string head, line;
  while (std::getline(in, line) && line.rfind("corners:", 0) != 0 && head.size() <= limits.max_bytes)
    head += line + "\n";
  const YAML::Node root = parseYamlDocument(head, path, limits);  // refuses a head past the limit
  if (!root.IsMap() || !root["job"] || !root["samples"])
    throw InputError(path + ": not a scanhead metrics.yaml (no job/samples)");
  return root;
}

/// The node at parts[i…] below \p node (recursive: assigning a yaml-cpp Node would rewrite the tree).
YAML::Node child(const YAML::Node& node, const std::vector<std::string>& parts, std::size_t i)
{
  if (i == parts.size())
    return node;
  if (!node.IsMap() || !node[parts[i]])
    return YAML::Node();
  return child(node[parts[i]], parts, i + 1);
}

/// The number at a dotted key; NaN where it is missing, null or not a number.
double lookup(const YAML::Node& root, const std::string& key)
{
  std::vector<std::string> parts;
  std::stringstream dotted(key);
  std::string part;
  while (std::getline(dotted, part, '.'))
    parts.push_back(part);
  const YAML::Node node = child(root, parts, 0);
  if (!node.IsDefined() || !node.IsScalar())
    return NAN;
  double value = NAN;
  const std::string text = node.Scalar();
  if (text == ".nan")
    return NAN;
  if (parseNumber(text, value) != NumberText::Ok)
    return NAN;
  return value;
}

std::string cell(double v, const std::string& unit)
{
  if (std::isnan(v))
    return "-";
  if (unit == "%")
    return fixedText(v, 2);
  if (unit == "samples")
    return fixedText(v, 0);
  return significantText(v, 4);
}

/// "A", "B" or "=" by the row's sense; "" where a value is missing or the figure ranks nothing.
const char* better(const ComparisonRow& r)
{
  if (std::isnan(r.a) || std::isnan(r.b) || r.better == Better::None)
    return "";
  if (r.a == r.b)
    return "=";
  return (r.b < r.a) == (r.better == Better::Lower) ? "B" : "A";
}

std::string change(const ComparisonRow& r)
{
  if (std::isnan(r.a) || std::isnan(r.b))
    return "";
  char text[64];
  if (r.unit == "%")
    std::snprintf(text, sizeof text, "%+.2f pt", r.b - r.a);
  else if (r.a != 0.0)
    std::snprintf(text, sizeof text, "%+.1f %%", 100.0 * (r.b - r.a) / std::abs(r.a));
  else
    std::snprintf(text, sizeof text, "%+.4g", r.b - r.a);
  return text;
}
}  // namespace

RunComparison compareMetricsFiles(const std::string& metrics_a, const std::string& metrics_b)
{
  const YAML::Node a = load(metrics_a), b = load(metrics_b);
  RunComparison c;
  c.name_a = a["job"].as<std::string>();
  c.name_b = b["job"].as<std::string>();
  for (const Figure& f : kFigures)
  {
    ComparisonRow row;
    row.key = f.key;
    row.label = f.label;
    row.unit = f.unit;
    row.a = lookup(a, f.key) * f.scale;
    row.b = lookup(b, f.key) * f.scale;
    row.better = f.better;
    c.rows.push_back(row);
  }
  return c;
}

std::string comparisonTable(const RunComparison& c)
{
  const int width = static_cast<int>(std::max<std::size_t>(12, std::max(c.name_a.size(), c.name_b.size())));
  char line[512];
  std::string out;
  std::snprintf(line, sizeof line, "%-34s %-8s %*s %*s %12s  %s\n", "figure", "unit", width, c.name_a.c_str(), width,
                c.name_b.c_str(), "B - A", "better");
  out += line;
  for (const ComparisonRow& r : c.rows)
  {
    std::snprintf(line, sizeof line, "%-34s %-8s %*s %*s %12s  %s\n", r.label.c_str(), r.unit.c_str(), width,
                  cell(r.a, r.unit).c_str(), width, cell(r.b, r.unit).c_str(), change(r).c_str(), better(r));
    out += line;
  }
  return out;
}

std::string comparisonYaml(const RunComparison& c)
{
  std::string out = "runs: [" + yamlQuoted(c.name_a) + ", " + yamlQuoted(c.name_b) + "]\nrows:\n";
  for (const ComparisonRow& r : c.rows)
    out += "  - {key: " + r.key + ", label: " + yamlQuoted(r.label) + ", unit: " + yamlQuoted(r.unit) +
           ", a: " + yamlNumber(r.a) + ", b: " + yamlNumber(r.b) + ", better: " +
           (r.better == Better::Lower    ? "lower"
            : r.better == Better::Higher ? "higher"
                                         : "none") +
           "}\n";
  return out;
}

std::vector<std::string> comparisonCells(const ComparisonRow& r)
{
  return {r.label, r.unit, cell(r.a, r.unit), cell(r.b, r.unit), change(r), better(r)};
}

std::string comparisonMarkdown(const RunComparison& c)
{
  std::string out =
      "| figure | unit | " + c.name_a + " | " + c.name_b + " | B − A | better |\n|---|---|---|---|---|---|\n";
  for (const ComparisonRow& r : c.rows)
  {
    out += "|";
    for (const std::string& text : comparisonCells(r))
      out += " " + text + " |";
    out += "\n";
  }
  return out;
}
}  // namespace scanhead
