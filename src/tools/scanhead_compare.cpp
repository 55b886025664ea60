// scanhead_compare: two runs side by side (THESIS Table 3.1), as a table, YAML, Markdown and a plot.
#include <filesystem>
#include <iostream>
#include <string>

#include "argument_cursor.hpp"
#include "scanhead/common/errors.hpp"
#include "scanhead/common/text_file.hpp"
#include "support/python_plots.hpp"
#include "scanhead/metrics/run_comparison.hpp"

namespace
{
const std::string kUsage =
    "usage: scanhead_compare RUN_A RUN_B [--names A,B] [--out DIR]\n"
    "  RUN_A, RUN_B  results folders of scanhead_run / the virtual machine (or their metrics.yaml)\n"
    "  --names       labels of the two runs (default: their job names)\n"
    "  --out         write comparison.yaml, comparison.md and comparison.png (scripts/plot_comparison.py) there\n";

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
    std::vector<std::string> runs;
    std::string names, out;
    ArgumentCursor args(argc, argv, kUsage);
    while (args.next())
    {
      if (args.is("--names"))
        names = args.value();
      else if (args.is("--out"))
        out = args.value();
      else if (!args.isOption())
        runs.push_back(args.arg());
      else
        args.reject();
    }
    if (runs.size() != 2)
      throw ConfigError("give exactly two runs (got " + std::to_string(runs.size()) + ")\n" + kUsage);
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
      runPythonScript("scripts/plot_comparison.py", { metricsPath(runs[0]), metricsPath(runs[1]), comparison.name_a,
                                                      comparison.name_b, (std::filesystem::path(out) / "comparison.png").string() });
      std::cout << "written to " << out << "/\n";
    }
    return 0;
  }
  catch (const std::exception& e)
  {
    std::cerr << "scanhead_compare: error: " << e.what() << "\n";
    return 1;
  }
}
