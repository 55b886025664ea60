// scanhead_optics: the optical chain of a machine with its assembly defects (SPEC §4, OPT):
// direct and inverse models, the URDF of the machine, the correction-table residual, the
// defects' influence maps, and the calibration of a machine from measured spots.
#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "argument_cursor.hpp"
#include "scanhead/chain/batch_chain.hpp"
#include "scanhead/common/text_file.hpp"
#include "scanhead/optics/calibration.hpp"
#include "scanhead/chain/config_io.hpp"
#include "scanhead/optics/correction_table.hpp"
#include "scanhead/common/errors.hpp"
#include "scanhead/optics/influence_map.hpp"
#include "scanhead/common/number_text.hpp"
#include "scanhead/optics/optical_defects.hpp"
#include "support/python_plots.hpp"

namespace
{
const char* kUsage =
    "usage: scanhead_optics COMMAND [--defects SET] [ARGUMENTS] [--config FILE] [--set section.key=value ...]\n"
    "commands:\n"
    "  trace THETA_X THETA_Y   the spot 'x y z' [m] of the machine at mechanical angles [rad], in its\n"
    "                          work-plane frame (the bed's own coordinates; z = 0 on the plane)\n"
    "  inverse X Y             the angles 'theta_x theta_y' [rad] that put the spot at (X, Y) [m]\n"
    "                          (Newton inverse of that machine)\n"
    "  urdf                    the machine's URDF: the package URDF (optics.urdf_path) with the\n"
    "                          defect set written into its defect joints\n"
    "  residual [--nodes N] [--probes P] [--interpolation bilinear|bicubic]\n"
    "                          spot error over the field (YAML) of the correction table built from the\n"
    "                          nominal model and of the one built from the machine's own model, both\n"
    "                          run on the machine (defaults: nc.igt.table_nodes, 129 probes per axis,\n"
    "                          nc.igt.table_interpolation)\n"
    "  influence --out DIR [--grid N]\n"
    "                          each of the 30 defects alone at 1 mm or 1 mrad: global shift at O_p and\n"
    "                          non-linear part over the field (DIR/influence.yaml, DIR/influence_chart.png)\n"
    "  field --out DIR [--grid N]\n"
    "                          the spot displacement the machine's defect set causes over the field\n"
    "                          (DIR/defect_field.csv, DIR/defect_field.png)\n"
    "  calibrate [--grid N] [--noise M] [--seed S]\n"
    "                          measure the machine's spots on an N x N grid of angles (noise M metres,\n"
    "                          default 1e-6; the machine is --defects, e.g. random:seed=7), estimate its\n"
    "                          defects from the nominal model, and report (YAML) the estimate, the\n"
    "                          identifiable combinations and the spot error over the field of the\n"
    "                          correction table before (nominal model) and after (identified model)\n"
    "options:\n"
    "  --defects SET  the machine (docs/defects.md): nominal | opt_table2 (OPT table 2) |\n"
    "                 random:seed=N[,mm=B][,mrad=B] | a defect set file (.yaml)\n"
    "                 (default: the config's optics.defects, nominal)\n"
    "  --config       configuration YAML (default: the package's config/scanhead.yaml)\n"
    "  --set          override one setting, e.g. --set optics.window_thickness_m=0.005 (repeatable)\n";

const char* kCommands = "trace, inverse, urdf, residual, influence, field, calibrate";

struct Arguments
{
  std::string command;
  std::vector<std::string> positional;  ///< after the command word
  std::string defects;                  ///< empty: the config's optics.defects
  int nodes = 0;                        ///< 0: nc.igt.table_nodes
  int probes = 129;
  std::string interpolation;            ///< empty: nc.igt.table_interpolation
  std::string out;                      ///< influence, field: output folder
  int grid = 0;                         ///< influence, field, calibrate: 0 = the command's default
  double noise_m = 1e-6;                ///< calibrate
  std::uint64_t seed = 1;               ///< calibrate: noise seed
  scanhead::ConfigArguments config;
  std::vector<std::string> given;       ///< the command's own options that were given
};

/// The options each command takes (besides --config and --set).
const std::vector<std::pair<std::string, std::vector<std::string>>> kCommandOptions = {
  { "trace", { "--defects" } },
  { "inverse", { "--defects" } },
  { "urdf", { "--defects" } },
  { "residual", { "--defects", "--nodes", "--probes", "--interpolation" } },
  { "influence", { "--out", "--grid" } },
  { "field", { "--defects", "--out", "--grid" } },
  { "calibrate", { "--defects", "--grid", "--noise", "--seed" } },
};

std::uint64_t seedArgument(const std::string& text)
{
  errno = 0;
  char* end = nullptr;
  const unsigned long long value = std::strtoull(text.c_str(), &end, 10);
  if (text.empty() || text.find_first_not_of("0123456789") != std::string::npos || *end != '\0' || errno == ERANGE)
    throw scanhead::ConfigError("--seed must be an integer in [0, 2^64) (got '" + text + "')");
  return static_cast<std::uint64_t>(value);
}

double nonNegativeNumber(const std::string& option, const std::string& text)
{
  double value = 0.0;
  if (scanhead::parseNumber(text, value) != scanhead::NumberText::Ok || !(value >= 0.0))
    throw scanhead::ConfigError(option + " must be a number >= 0 (got '" + text + "')");
  return value;
}

Arguments parse(int argc, char** argv)
{
  Arguments a;
  scanhead::ArgumentCursor args(argc, argv, kUsage);
  while (args.next())
  {
    if (a.config.take(args))
      continue;
    if (args.isOption())
      a.given.push_back(args.arg());
    if (args.is("--defects"))
      a.defects = args.value();
    else if (args.is("--nodes"))
      a.nodes = scanhead::integerAtLeastTwo("--nodes", args.value());
    else if (args.is("--probes"))
      a.probes = scanhead::integerAtLeastTwo("--probes", args.value());
    else if (args.is("--interpolation"))
      a.interpolation = args.value();
    else if (args.is("--out"))
      a.out = args.value();
    else if (args.is("--grid"))
      a.grid = scanhead::integerAtLeastTwo("--grid", args.value());
    else if (args.is("--noise"))
      a.noise_m = nonNegativeNumber("--noise", args.value());
    else if (args.is("--seed"))
      a.seed = seedArgument(args.value());
    else if (args.isOption())
      args.reject();
    else if (a.command.empty())
      a.command = args.arg();
    else
      a.positional.push_back(args.arg());
  }
  if (a.command.empty())
    throw scanhead::ConfigError(std::string("no command (commands: ") + kCommands + ")\n" + kUsage);
  const auto command = std::find_if(kCommandOptions.begin(), kCommandOptions.end(),
                                    [&](const auto& c) { return c.first == a.command; });
  if (command == kCommandOptions.end())
    throw scanhead::ConfigError("unknown command '" + a.command + "' (commands: " + kCommands + ")\n" + kUsage);
  for (const std::string& option : a.given)
  {
    if (std::find(command->second.begin(), command->second.end(), option) == command->second.end())
      throw scanhead::ConfigError(option + " is not an option of " + a.command + "\n" + kUsage);
  }
  if ((a.command == "influence" || a.command == "field") && a.out.empty())
    throw scanhead::ConfigError(a.command + " needs --out DIR\n" + kUsage);
  return a;
}

/// The positional arguments of the command, as numbers named \p names (their count).
std::vector<double> numbers(const Arguments& a, const std::vector<std::string>& names)
{
  std::string expected;
  for (const std::string& n : names)
    expected += " " + n;
  if (a.positional.size() != names.size())
    throw scanhead::ConfigError(a.command + " takes" + (names.empty() ? std::string(" no arguments") : expected) +
                                " (got " + std::to_string(a.positional.size()) + " argument" +
                                (a.positional.size() == 1 ? "" : "s") + ")\n" + kUsage);
  std::vector<double> values(names.size());
  for (std::size_t k = 0; k < names.size(); ++k)
  {
    const scanhead::NumberText parsed = scanhead::parseNumber(a.positional[k], values[k]);
    if (parsed != scanhead::NumberText::Ok)
      throw scanhead::ConfigError(names[k] + " must be a finite number (got '" + a.positional[k] + "')");
  }
  return values;
}

/// The machine: the nominal URDF with the defect set applied.
struct Machine
{
  scanhead::ChainConfig config;
  std::string urdf_path;
  scanhead::OpticalGeometry nominal;
  scanhead::DefectSet defects;
  scanhead::OpticalModel optics;
};

Machine loadMachine(const Arguments& a)
{
  using namespace scanhead;
  ChainConfig config = a.config.load();
  if (!a.defects.empty())
    config.optics.defects = a.defects;
  const DefectSet defects = loadDefects(config.optics);  // the forms of defectSetByName, files resolved
  const std::string urdf_path = resolvePackagePath(config.optics.urdf_path);
  const OpticalGeometry nominal = geometryFromUrdfFile(urdf_path);
  return Machine{ config, urdf_path, nominal, defects, loadOpticalModel(config.optics) };  // as the batch runner
}

void printReport(const char* key, const scanhead::TableErrorReport& r)
{
  using scanhead::fullPrecisionText;
  std::cout << key << ": {max_error_m: " << fullPrecisionText(r.max_error_m)
            << ", rms_error_m: " << fullPrecisionText(r.rms_error_m) << ", worst_point_m: ["
            << fullPrecisionText(r.worst_point_m.x()) << ", " << fullPrecisionText(r.worst_point_m.y()) << "]}\n";
}

int residual(const Arguments& a, const Machine& m)
{
  using namespace scanhead;
  numbers(a, {});
  const TableInterpolation interpolation =
      a.interpolation.empty()
          ? parseTableInterpolation(m.config.nc.igt.table_interpolation, "nc.igt.table_interpolation")
          : parseTableInterpolation(a.interpolation, "--interpolation");
  const int nodes = a.nodes != 0 ? a.nodes : m.config.nc.igt.table_nodes;
  const double h = m.config.optics.field_half_width_m;
  const OpticalModel nominal(m.nominal, m.config.optics);
  const CorrectionTable nominal_table = CorrectionTable::build(nominal, nodes, h);
  const CorrectionTable own_table = CorrectionTable::build(m.optics, nodes, h);
  std::cout << "defects: " << m.defects.name << "\n"
            << "nodes: " << nodes << "\n"
            << "half_width_m: " << fullPrecisionText(h) << "\n"
            << "interpolation: " << (interpolation == TableInterpolation::Bilinear ? "bilinear" : "bicubic") << "\n"
            << "probes_per_axis: " << a.probes << "\n";
  printReport("nominal_table", measureTableError(nominal_table, interpolation, m.optics, a.probes));
  printReport("own_table", measureTableError(own_table, interpolation, m.optics, a.probes));
  return 0;
}

int influence(const Arguments& a, const Machine& m)
{
  using namespace scanhead;
  numbers(a, {});
  std::filesystem::create_directories(a.out);
  const std::vector<InfluenceRow> rows = influenceTable(m.nominal, m.config.optics, a.grid != 0 ? a.grid : 21);
  const std::string yaml = a.out + "/influence.yaml";
  writeTextFile(yaml, influenceYaml(rows));
  runPythonScript("scripts/plot_optics.py", { "influence", yaml, a.out + "/influence_chart.png" });
  std::cout << "influence of the 30 defects written to " << yaml << " and " << a.out << "/influence_chart.png\n";
  return 0;
}

int field(const Arguments& a, const Machine& m)
{
  using namespace scanhead;
  numbers(a, {});
  std::filesystem::create_directories(a.out);
  const DefectField f = defectField(m.nominal, m.config.optics, m.defects, a.grid != 0 ? a.grid : 21);
  const std::string csv = a.out + "/defect_field.csv";
  writeTextFile(csv, defectFieldCsv(f));
  double worst = 0.0;
  for (const Eigen::Vector2d& d : f.displacement_m)
    worst = std::max(worst, d.norm());
  runPythonScript("scripts/plot_optics.py",
                  { "field", csv, a.out + "/defect_field.png", "--title", "defect set " + m.defects.name });
  std::cout << "defects " << m.defects.name << ": spot displacement up to " << worst * 1e6 << " um over the field; "
            << csv << ", " << a.out << "/defect_field.png\n";
  return 0;
}

int calibrate(const Arguments& a, const Machine& m)
{
  using namespace scanhead;
  numbers(a, {});
  const OpticalModel nominal(m.nominal, m.config.optics);
  const std::vector<Eigen::Vector2d> angles = fieldAngleGrid(nominal, a.grid != 0 ? a.grid : 15);
  const std::vector<SpotMeasurement> measured = simulateMeasurements(m.optics, angles, a.noise_m, a.seed);
  CalibrationOptions options;
  options.noise_m = a.noise_m;
  const CalibrationResult result = calibrate(m.nominal, m.config.optics, measured, options);
  const OpticalModel identified(applyDefects(m.nominal, result.estimate), m.config.optics);
  // The NC's table built from the nominal model, then from the identified one, run on the machine.
  const double h = m.config.optics.field_half_width_m;
  const int nodes = m.config.nc.igt.table_nodes;
  std::cout << "machine: " << m.defects.name << "\n"
            << "measurements: " << measured.size() << "\n"
            << "noise_m: " << fullPrecisionText(a.noise_m) << "\n"
            << "table: {nodes: " << nodes << ", interpolation: bicubic, probes_per_axis: 129}\n";
  printReport("before_nominal_table",
              measureTableError(CorrectionTable::build(nominal, nodes, h), TableInterpolation::Bicubic, m.optics, 129));
  printReport("after_identified_table",
              measureTableError(CorrectionTable::build(identified, nodes, h), TableInterpolation::Bicubic, m.optics, 129));
  std::cout << calibrationYaml(result);
  return 0;
}
}  // namespace

int main(int argc, char** argv)
{
  using namespace scanhead;
  try
  {
    const Arguments args = parse(argc, argv);
    const Machine machine = loadMachine(args);
    if (args.command == "trace")
    {
      const std::vector<double> q = numbers(args, { "THETA_X", "THETA_Y" });
      const OpticalGeometry& g = machine.optics.geometry();
      for (const double angle : q)
      {
        if (angle < g.joint_lower_rad || angle > g.joint_upper_rad)
          throw ConfigError("angle " + fullPrecisionText(angle) + " rad is outside the galvos' range [" +
                            fullPrecisionText(g.joint_lower_rad) + ", " + fullPrecisionText(g.joint_upper_rad) + "]");
      }
      const Eigen::Vector2d spot = machine.optics.spot(Eigen::Vector2d(q[0], q[1]));
      // The spot lies on the plane z = 0 of the work-plane frame.
      std::cout << fullPrecisionText(spot.x()) << " " << fullPrecisionText(spot.y()) << " 0\n";
    }
    else if (args.command == "inverse")
    {
      const std::vector<double> x = numbers(args, { "X", "Y" });
      const Eigen::Vector2d q = machine.optics.inverse(Eigen::Vector2d(x[0], x[1]));
      std::cout << fullPrecisionText(q.x()) << " " << fullPrecisionText(q.y()) << "\n";
    }
    else if (args.command == "urdf")
    {
      numbers(args, {});
      std::cout << urdfWithDefects(readUrdfFile(machine.urdf_path), machine.defects, machine.urdf_path);
    }
    else if (args.command == "residual")
      return residual(args, machine);
    else if (args.command == "influence")
      return influence(args, machine);
    else if (args.command == "field")
      return field(args, machine);
    else
      return calibrate(args, machine);
    return 0;
  }
  catch (const std::exception& e)
  {
    std::cerr << "scanhead_optics: error: " << e.what() << "\n";
    return 1;
  }
}
