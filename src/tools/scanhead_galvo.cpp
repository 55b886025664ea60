// scanhead_galvo: the galvo servo's own tools — loop analysis, identification, KM0 protocol.
#include <cstdlib>
#include <iostream>
#include <string>
#include <vector>

#include "scanhead/chain/batch_chain.hpp"
#include "scanhead/chain/config_io.hpp"
#include "scanhead/common/errors.hpp"
#include "scanhead/servo/hinf/hinf_loops.hpp"
#include "scanhead/servo/identification/identification_report.hpp"
#include "scanhead/servo/km0/km0_config.hpp"
#include "scanhead/servo/km0/km0_report.hpp"
#include "scanhead/servo/loop_analysis.hpp"
#include "support/command_line.hpp"
#include "support/python_plots.hpp"
#include "support/tool_errors.hpp"

namespace
{
struct Arguments
{
  std::string command;
  int axis = -1;
  scanhead::ConfigArguments config;
  std::string km0_config = "config/km0.yaml";
  std::string out;
  std::string position_controller;  ///< loops: pd | hinf ("": servo.position_controller)
};

/// \brief The command and its options into \p a. \return false after --help
bool parse(int argc, char** argv, Arguments& a)
{
  CLI::App app("The galvo servo's own tools: loop analysis, identification, KM0 protocol.", "scanhead_galvo");
  scanhead::configureApp(app);
  std::string axis;
  app.add_option("--axis", axis, "the galvo axis")
      ->type_name("x|y")
      ->required()
      ->transform(scanhead::check::oneOf({"x", "y"}));
  a.config.addTo(app, "servo.y.plant.coulomb_torque_nm=6e-5");
  CLI::App* loops = app.add_subcommand(
      "loops",
      "crossovers, phase margins and closed-loop bandwidth of the axis's controller (YAML);\n"
      "hinf: also gamma, gain margin, peaks of S, KS, SG, T; with --out DIR hinf_bode.csv and its plot");
  loops->add_option("--position-controller", a.position_controller, "default: servo.position_controller")
      ->type_name("pd|hinf")
      ->transform(scanhead::check::oneOf({"pd", "hinf"}));
  loops->add_option("--out", a.out, "hinf: folder for hinf_bode.csv and hinf_loops.png (Fig. 3.5 style)")
      ->type_name("DIR");
  CLI::App* identify =
      app.add_subcommand("identify",
                         "PRBS identification of the simulated galvo: true vs identified R, L, Kc, B, Jeq (YAML);\n"
                         "with --out DIR also bode.csv and Bode plots");
  identify->add_option("--out", a.out, "folder for bode.csv and the Bode plots")->type_name("DIR");
  CLI::App* km0 = app.add_subcommand("km0", "the KM0 maintenance protocol (steps, large steps, ramps) with verdicts");
  km0->add_option("--out", a.out, "folder for km0_report.yaml, CSV and plots")->type_name("DIR")->required();
  km0->add_option("--km0-config", a.km0_config, "KM0 thresholds (default: the package's config/km0.yaml)")
      ->type_name("FILE");
  app.require_subcommand(0, 1);  // one command; a missing one is named by parseCommandLine
  if (!scanhead::parseCommandLine(app, argc, argv))
    return false;
  a.command = app.get_subcommands().front()->get_name();
  a.axis = axis == "x" ? 0 : 1;
  return true;
}
}  // namespace

int main(int argc, char** argv)
{
  using namespace scanhead;
  try
  {
    Arguments args;
    if (!parse(argc, argv, args))
      return 0;
    ChainConfig config = args.config.load();
    if (!args.position_controller.empty())
      config.servo.position_controller = args.position_controller;
    const AxisLoopConfig& axis = args.axis == 0 ? config.servo.x : config.servo.y;
    if (args.command == "loops" && config.servo.position_controller == "hinf")
      std::cout << hinfLoopsReportYaml(config.servo, args.axis, args.out,
                                       pythonPlotHook("scripts/plot_hinf_loops.py", "H-infinity loop plots"));
    else if (args.command == "loops")
      std::cout << loopsReportYaml(config.servo, args.axis);
    else if (args.command == "identify")
      std::cout << identificationReport(axis.plant, IdentificationConfig{}, args.out,
                                        pythonPlotHook("scripts/plot_bode.py", "Bode plots"));
    else
    {
      const Km0Config km0 = loadKm0Config(resolvePackagePath(args.km0_config));
      std::cout << km0Report(config.servo, args.axis, config.nc.period_s, km0, args.out,
                             pythonPlotHook("scripts/plot_km0.py", "KM0 plots"));
    }
    return 0;
  }
  catch (const std::exception& e)
  {
    std::cerr << "scanhead_galvo: error: " << scanhead::toolErrorText(e) << "\n";
    return 1;
  }
}
