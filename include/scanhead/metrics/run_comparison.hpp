/// \file run_comparison.hpp
/// \brief Two runs side by side (e.g. two recipes, two controllers), as THESIS Table 3.1: the layer
/// time, the fill rate, the contour-error shares by kind and definition, speed, energy and servo
/// figures, read back from each run's metrics.yaml.
#pragma once

#include <string>
#include <vector>

namespace scanhead
{
/// \brief Which way a figure improves (None: it describes the run, it does not rank it).
enum class Better
{
  Lower,
  Higher,
  None
};

/// \brief One compared figure: its name, unit, the two values and which way is better.
struct ComparisonRow
{
  std::string key;    ///< path in metrics.yaml, e.g. "contour_error.same_instant.contour.share_under_10um"
  std::string label;  ///< human-readable, e.g. "contours < 10 um (same instant)"
  std::string unit;   ///< shown unit ("%", "s", "um"…): values are already scaled to it
  double a = 0.0, b = 0.0;
  Better better = Better::None;
};

struct RunComparison
{
  std::string name_a, name_b;  ///< labels of the runs (job names unless given)
  std::vector<ComparisonRow> rows;
};

/// \brief Reads two metrics.yaml files and builds the rows (a figure missing or null in a run, e.g.
/// nearest_path on a job too long for it, reads NaN there).
/// \throws InputError naming the file if one is missing or is not a scanhead metrics.yaml
RunComparison compareMetricsFiles(const std::string& metrics_a, const std::string& metrics_b);

/// \brief The table as aligned text: figure, run A, run B, B − A (points for shares, else relative)
/// and which run is better by the row's sense.
std::string comparisonTable(const RunComparison& comparison);
/// \brief The same as YAML (full precision): {runs: [a, b], rows: [{key, label, unit, a, b}]}.
std::string comparisonYaml(const RunComparison& comparison);
/// \brief One row as text: figure, unit, run A, run B, B − A, better (the cells of every table form).
std::vector<std::string> comparisonCells(const ComparisonRow& row);
/// \brief The same as a Markdown table (for reports and READMEs).
std::string comparisonMarkdown(const RunComparison& comparison);
}  // namespace scanhead
