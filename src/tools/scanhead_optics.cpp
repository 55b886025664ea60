// scanhead_optics: the optical chain of a machine with its assembly defects (SPEC §4, OPT):
// direct and inverse models, the URDF of the machine, the correction-table residual, the
// defects' influence maps, and the calibration of a machine from measured spots.
#include <algorithm>
#include <filesystem>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "scanhead/chain/batch_chain.hpp"
#include "scanhead/chain/config_io.hpp"
#include "scanhead/common/errors.hpp"
#include "scanhead/common/number_text.hpp"
#include "scanhead/common/text_file.hpp"
#include "scanhead/optics/calibration.hpp"
#include "scanhead/optics/correction_table.hpp"
#include "scanhead/optics/influence_map.hpp"
#include "scanhead/optics/optical_defects.hpp"
#include "support/command_line.hpp"
#include "support/python_plots.hpp"
#include "support/tool_errors.hpp"

namespace
{
struct Arguments
{
  std::string command;
  std::vector<double> point = {0.0, 0.0};  ///< trace: THETA_X THETA_Y [rad]; inverse: X Y [m]
  std::string defects;                     ///< empty: the config's optics.defects
  int nodes = 0;                           ///< 0: nc.igt.table_nodes
  int probes = 129;
  std::string interpolation;  ///< empty: nc.igt.table_interpolation
  std::string out;            ///< influence, field: output folder
  int grid = 0;               ///< influence, field, calibrate: 0 = the command's default
  double noise_m = 1e-6;      ///< calibrate
  std::uint64_t seed = 1;     ///< calibrate: noise seed
  scanhead::ConfigArguments config;
};

/// Most grid points per axis (--grid): N² spots, each a forward model, N² × 18 for influence; the
/// calibration's least-squares fit works on 2N² residuals.
constexpr int kMaxGrid = 201;

/// \brief The command and its options into \p a. \return false after --help
bool parse(int argc, char** argv, Arguments& a)
{
  using namespace scanhead;
  CLI::App app(
      "The optical chain of a machine with its assembly defects (SPEC §4, OPT): direct and inverse\n"
      "models, the machine's URDF, the correction-table residual, the defects' influence maps,\n"
      "and the calibration of a machine from measured spots.",
      "scanhead_optics");
  configureApp(app);
  CLI::Option* defects = app.add_option("--defects", a.defects,
                                        "the machine (docs/defects.md): nominal | opt_table2 (OPT table 2) |\n"
                                        "random:seed=N[,mm=B][,mrad=B] | a defect set file (.yaml)\n"
                                        "(default: the config's optics.defects, nominal); not with influence")
                             ->type_name("SET");
  a.config.addTo(app, "optics.window_thickness_m=0.005");

  const auto point = [&](CLI::App* command, const char* first, const char* second, const char* unit) {
    command->add_option(first, a.point[0], unit)->type_name("NUMBER")->required()->transform(check::finiteNumber());
    command->add_option(second, a.point[1], unit)->type_name("NUMBER")->required()->transform(check::finiteNumber());
  };
  const auto grid = [&](CLI::App* command, const char* help) {
    command->add_option("--grid", a.grid, help)->type_name("N")->transform(check::integerIn(2, kMaxGrid));
  };
  point(app.add_subcommand("trace",
                           "the spot 'x y z' [m] of the machine at mechanical angles [rad], in its\n"
                           "work-plane frame (the bed's own coordinates; z = 0 on the plane)"),
        "THETA_X", "THETA_Y", "mechanical angle [rad]");
  point(app.add_subcommand("inverse",
                           "the angles 'theta_x theta_y' [rad] that put the spot at (X, Y) [m]\n"
                           "(Newton inverse of that machine)"),
        "X", "Y", "spot coordinate in the work-plane frame [m]");
  app.add_subcommand("urdf",
                     "the machine's URDF: the package URDF (optics.urdf_path) with the\n"
                     "defect set written into its defect joints");
  CLI::App* residual =
      app.add_subcommand("residual",
                         "spot error over the field (YAML) of the correction table built from the nominal model\n"
                         "and of the one built from the machine's own model, both run on the machine");
  residual->add_option("--nodes", a.nodes, "table nodes per axis (default: nc.igt.table_nodes)")
      ->type_name("N")
      ->transform(check::integerAtLeast(2));
  residual->add_option("--probes", a.probes, "probes per axis, 2 to 2049 (default 129)")
      ->type_name("P")
      ->transform(check::integerIn(2, check::kMaxProbesPerAxis));
  residual->add_option("--interpolation", a.interpolation, "default: nc.igt.table_interpolation")
      ->type_name("bilinear|bicubic");
  CLI::App* influence =
      app.add_subcommand("influence",
                         "each of the 30 defects alone at 1 mm or 1 mrad: global shift at O_p and non-linear part\n"
                         "over the field (DIR/influence.yaml, DIR/influence_chart.png)");
  influence->add_option("--out", a.out, "output folder")->type_name("DIR")->required();
  grid(influence, "field grid per axis (2 to 201, default 21)");
  CLI::App* field = app.add_subcommand("field",
                                       "the spot displacement the machine's defect set causes over the field\n"
                                       "(DIR/defect_field.csv, DIR/defect_field.png)");
  field->add_option("--out", a.out, "output folder")->type_name("DIR")->required();
  grid(field, "field grid per axis (2 to 201, default 21)");
  CLI::App* calibrate =
      app.add_subcommand("calibrate",
                         "measure the machine's spots on an N x N grid of angles, estimate its defects from the\n"
                         "nominal model, and report (YAML) the estimate, the identifiable combinations and the\n"
                         "spot error over the field of the correction table before (nominal model) and after\n"
                         "(identified model); the machine is --defects, e.g. random:seed=7");
  grid(calibrate, "angle grid per axis (2 to 201, default 15)");
  calibrate->add_option("--noise", a.noise_m, "measurement noise [m] (default 1e-6)")
      ->type_name("M")
      ->transform(check::nonNegativeNumber());
  calibrate->add_option("--seed", a.seed, "noise seed (default 1)")->type_name("S")->transform(check::unsigned64());
  app.require_subcommand(0, 1);  // one command; a missing one is named by parseCommandLine
  if (!parseCommandLine(app, argc, argv))
    return false;
  a.command = app.get_subcommands().front()->get_name();
  if (influence->parsed() && defects->count() > 0)
    throw ConfigError("--defects is not an option of influence (it measures each defect alone)");
  return true;
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
  return Machine{config, urdf_path, nominal, defects, loadOpticalModel(config.optics)};  // as the batch runner
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
  std::filesystem::create_directories(a.out);
  const std::vector<InfluenceRow> rows = influenceTable(m.nominal, m.config.optics, a.grid != 0 ? a.grid : 21);
  const std::string yaml = a.out + "/influence.yaml";
  writeTextFile(yaml, influenceYaml(rows));
  runPythonScript("scripts/plot_optics.py", {"influence", yaml, a.out + "/influence_chart.png"});
  std::cout << "influence of the 30 defects written to " << yaml << " and " << a.out << "/influence_chart.png\n";
  return 0;
}

int field(const Arguments& a, const Machine& m)
{
  using namespace scanhead;
  std::filesystem::create_directories(a.out);
  const DefectField f = defectField(m.nominal, m.config.optics, m.defects, a.grid != 0 ? a.grid : 21);
  const std::string csv = a.out + "/defect_field.csv";
  writeTextFile(csv, defectFieldCsv(f));
  double worst = 0.0;
  for (const Eigen::Vector2d& d : f.displacement_m)
    worst = std::max(worst, d.norm());
  runPythonScript("scripts/plot_optics.py",
                  {"field", csv, a.out + "/defect_field.png", "--title", "defect set " + m.defects.name});
  std::cout << "defects " << m.defects.name << ": spot displacement up to " << worst * 1e6 << " um over the field; "
            << csv << ", " << a.out << "/defect_field.png\n";
  return 0;
}

int calibrate(const Arguments& a, const Machine& m)
{
  using namespace scanhead;
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
  printReport("after_identified_table", measureTableError(CorrectionTable::build(identified, nodes, h),
                                                          TableInterpolation::Bicubic, m.optics, 129));
  std::cout << calibrationYaml(result);
  return 0;
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
    const Machine machine = loadMachine(args);
    if (args.command == "trace")
    {
      const std::vector<double>& q = args.point;
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
      const std::vector<double>& x = args.point;
      const Eigen::Vector2d q = machine.optics.inverse(Eigen::Vector2d(x[0], x[1]));
      std::cout << fullPrecisionText(q.x()) << " " << fullPrecisionText(q.y()) << "\n";
    }
    else if (args.command == "urdf")
      std::cout << urdfWithDefects(readUrdfFile(machine.urdf_path), machine.defects, machine.urdf_path);
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
    std::cerr << "scanhead_optics: error: " << scanhead::toolErrorText(e) << "\n";
    return 1;
  }
}
