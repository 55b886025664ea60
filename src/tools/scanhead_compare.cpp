// scanhead_compare: two runs side by side (THESIS Table 3.1), as a table, YAML, Markdown and a plot.
#include <filesystem>
#include <iostream>
#include <string>

#include "scanhead/common/errors.hpp"
#include "scanhead/common/text_file.hpp"
#include "scanhead/metrics/run_comparison.hpp"
#include "scanhead/report/comparison_report.hpp"
#include "support/command_line.hpp"
#include "support/python_plots.hpp"
#include "support/tool_errors.hpp"

namespace
{
std::string metricsPath(const std::string& run)
{
  return std::filesystem::is_directory(run) ? (std::filesystem::path(run) / "metrics.yaml").string() : run;
}

}  // namespace

int main(int argc, char** argv)
{
  using namespace scanhead;
  try
  {
    std::string run_a, run_b, names, out;
    CLI::App app("Two runs side by side (THESIS Table 3.1), as a table, YAML, Markdown and a plot.",
                 "scanhead_compare");
    configureApp(app);
    app.add_option("RUN_A", run_a, "results folder of scanhead_run / the virtual machine (or its metrics.yaml)")
        ->required();
    app.add_option("RUN_B", run_b, "the second run, likewise")->required();
    app.add_option("--names", names, "labels of the two runs (default: their job names)")->type_name("A,B");
    app.add_option("--out", out,
                   "write comparison.yaml, comparison.md, comparison.png (scripts/plot_comparison.py) and "
                   "comparison.html (the page with both) there")
        ->type_name("DIR");
    if (!parseCommandLine(app, argc, argv))
      return 0;
    const std::vector<std::string> runs{run_a, run_b};
    RunComparison comparison = compareMetricsFiles(metricsPath(runs[0]), metricsPath(runs[1]));
    if (!names.empty())
    {
      const std::size_t comma = names.find(',');
      if (comma == std::string::npos || comma == 0 || comma + 1 == names.size())
        throw ConfigError("--names: expected A,B (got '" + names + "')");
      comparison.name_a = names.substr(0, comma);
      comparison.name_b = names.substr(comma + 1);
    }
    std::cout << comparisonTable(comparison);
    if (!out.empty())
    {
      std::filesystem::create_directories(out);
      writeTextFile(std::filesystem::path(out) / "comparison.yaml", comparisonYaml(comparison));
      writeTextFile(std::filesystem::path(out) / "comparison.md", comparisonMarkdown(comparison));
      runPythonScript("scripts/plot_comparison.py",
                      {metricsPath(runs[0]), metricsPath(runs[1]), comparison.name_a, comparison.name_b,
                       (std::filesystem::path(out) / "comparison.png").string()});
      // Last: the page embeds the chart.
      writeTextFile(std::filesystem::path(out) / "comparison.html",
                    comparisonReportHtml(comparison, runs[0], runs[1],
                                         readFileOrEmpty((std::filesystem::path(out) / "comparison.png").string())));
      std::cout << "written to " << out << "/\n";
    }
    return 0;
  }
  catch (const std::exception& e)
  {
    std::cerr << "scanhead_compare: error: " << scanhead::toolErrorText(e) << "\n";
    return 1;
  }
}
