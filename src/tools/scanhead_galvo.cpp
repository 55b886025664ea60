// scanhead_galvo: the galvo servo's own tools — loop analysis, identification, KM0 protocol.
#include <cstdlib>
#include <iostream>
#include <string>
#include <vector>

#include "argument_cursor.hpp"
#include "scanhead/chain/batch_chain.hpp"
#include "scanhead/chain/config_io.hpp"
#include "scanhead/common/errors.hpp"
#include "scanhead/servo/identification/identification_report.hpp"
#include "scanhead/servo/km0/km0_config.hpp"
#include "scanhead/servo/km0/km0_report.hpp"
#include "scanhead/servo/loop_analysis.hpp"
#include "support/python_plots.hpp"

namespace
{
const char* kUsage =
    "usage: scanhead_galvo COMMAND --axis x|y [--config FILE] [--set section.key=value ...] [options]\n"
    "commands:\n"
    "  loops     crossovers, phase margins and closed-loop bandwidth of the axis's cascade (YAML)\n"
    "  identify  PRBS identification of the simulated galvo: true vs identified R, L, Kc, B, Jeq (YAML);\n"
    "            with --out DIR also bode.csv and Bode plots\n"
    "  km0       the KM0 maintenance protocol (steps, large steps, ramps) with verdicts;\n"
    "            --out DIR (required) gets km0_report.yaml, CSV and plots; --km0-config FILE\n"
    "            (default: the package's config/km0.yaml)\n";

struct Arguments
{
  std::string command;
  int axis = -1;
  scanhead::ConfigArguments config;
  std::string km0_config = "config/km0.yaml";
  std::string out;
};

Arguments parse(int argc, char** argv)
{
  Arguments a;
  scanhead::ArgumentCursor args(argc, argv, kUsage);
  while (args.next())
  {
    if (a.config.take(args))
      continue;
    if (args.is("--axis"))
    {
      const std::string axis = args.value();
      if (axis != "x" && axis != "y")
        throw scanhead::ConfigError("--axis must be x or y (got '" + axis + "')");
      a.axis = axis == "x" ? 0 : 1;
    }
    else if (args.is("--km0-config"))
      a.km0_config = args.value();
    else if (args.is("--out"))
      a.out = args.value();
    else if (a.command.empty() && !args.isOption())
      a.command = args.arg();
    else
      args.reject();
  }
  if (a.command != "loops" && a.command != "identify" && a.command != "km0")
    throw scanhead::ConfigError((a.command.empty() ? std::string("no command") : "unknown command '" + a.command + "'") +
                                "\n" + kUsage);
  if (a.axis < 0)
    throw scanhead::ConfigError("--axis x|y is required\n" + std::string(kUsage));
  return a;
}
}  // namespace

int main(int argc, char** argv)
{
  using namespace scanhead;
  try
  {
    const Arguments args = parse(argc, argv);
    const ChainConfig config = args.config.load();
    const AxisLoopConfig& axis = args.axis == 0 ? config.servo.x : config.servo.y;
    if (args.command == "loops")
      std::cout << loopsReportYaml(config.servo, args.axis);
    else if (args.command == "identify")
      std::cout << identificationReport(axis.plant, IdentificationConfig{}, args.out,
                                        pythonPlotHook("scripts/plot_bode.py", "Bode plots"));
    else
    {
      if (args.out.empty())
        throw ConfigError("km0 needs --out DIR for its report, CSV files and plots");
      const Km0Config km0 = loadKm0Config(resolvePackagePath(args.km0_config));
      std::cout << km0Report(config.servo, args.axis, config.nc.period_s, km0, args.out,
                             pythonPlotHook("scripts/plot_km0.py", "KM0 plots"));
    }
    return 0;
  }
  catch (const std::exception& e)
  {
    std::cerr << "scanhead_galvo: error: " << e.what() << "\n";
    return 1;
  }
}
