// scanhead_table: builds (or loads) the NC correction table and reports its interpolation error
// against the optics, optionally with assembly defects (SPEC §2.2, §4).
#include <iostream>
#include <string>
#include <vector>

#include "scanhead/chain/batch_chain.hpp"
#include "scanhead/chain/config_io.hpp"
#include "scanhead/common/errors.hpp"
#include "scanhead/common/number_text.hpp"
#include "scanhead/optics/correction_table.hpp"
#include "scanhead/optics/optical_defects.hpp"
#include "support/command_line.hpp"
#include "support/tool_errors.hpp"

namespace
{
struct Arguments
{
  int nodes = 0;  ///< 0: from the config
  std::string interpolation;
  std::string defects;
  int probes = 257;
  std::string save;
  std::string load;
  scanhead::ConfigArguments config;
};

/// \brief The options into \p a. \return false after --help
bool parse(int argc, char** argv, Arguments& a)
{
  CLI::App app(
      "Builds the correction table from the optics (Newton inverse at N x N nodes over the field\n"
      "[-h, h]^2, h = optics.field_half_width_m), or loads it, and prints its error |h(q_table(x)) - x|\n"
      "over P x P probes as YAML.",
      "scanhead_table");
  scanhead::configureApp(app);
  CLI::Option* nodes =
      app.add_option("--nodes", a.nodes, "nodes per axis (default: nc.igt.table_nodes, 65); not with --load")
          ->type_name("N")
          ->transform(scanhead::check::integerAtLeast(2));
  app.add_option("--interpolation", a.interpolation,
                 "bilinear (THESIS) or bicubic (default: nc.igt.table_interpolation)")
      ->type_name("bilinear|bicubic");
  app.add_option("--defects", a.defects,
                 "assembly defects of the optics the table is built and checked on (docs/defects.md):\n"
                 "nominal | opt_table2 (OPT table 2) | random:seed=N[,mm=B][,mrad=B] | a defect set\n"
                 "file (.yaml) (default: the config's optics.defects, nominal)")
      ->type_name("SET");
  app.add_option("--probes", a.probes, "probes per axis, 2 to 2049 (default 257)")
      ->type_name("P")
      ->transform(scanhead::check::integerIn(2, scanhead::check::kMaxProbesPerAxis));
  CLI::Option* save =
      app.add_option("--save", a.save, "write the built table (docs/correction_table.md)")->type_name("FILE");
  CLI::Option* load =
      app.add_option("--load", a.load, "check a saved table instead of building one")->type_name("FILE");
  load->excludes(nodes)->excludes(save);
  a.config.addTo(app, "optics.field_half_width_m=0.15");
  return scanhead::parseCommandLine(app, argc, argv);
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
    const ChainConfig config = args.config.load();
    const TableInterpolation interpolation =
        args.interpolation.empty()
            ? parseTableInterpolation(config.nc.igt.table_interpolation, "nc.igt.table_interpolation")
            : parseTableInterpolation(args.interpolation, "--interpolation");

    OpticsConfig machine = config.optics;
    if (!args.defects.empty())
      machine.defects = args.defects;
    const DefectSet defects = loadDefects(machine);         // the forms of defectSetByName, files resolved
    const OpticalModel optics = loadOpticalModel(machine);  // the machine as the batch runner builds it

    const CorrectionTable table =
        args.load.empty() ? CorrectionTable::build(optics, args.nodes != 0 ? args.nodes : config.nc.igt.table_nodes,
                                                   config.optics.field_half_width_m)
                          : CorrectionTable::load(args.load);
    if (!args.save.empty())
      table.save(args.save);
    const TableErrorReport report = measureTableError(table, interpolation, optics, args.probes);

    std::cout << "nodes: " << table.nodes() << "\n"
              << "half_width_m: " << fullPrecisionText(table.halfWidth()) << "\n"
              << "interpolation: " << (interpolation == TableInterpolation::Bilinear ? "bilinear" : "bicubic") << "\n"
              << "defects: " << defects.name << "\n"
              << "probes_per_axis: " << report.probes_per_axis << "\n"
              << "max_error_m: " << fullPrecisionText(report.max_error_m) << "\n"
              << "rms_error_m: " << fullPrecisionText(report.rms_error_m) << "\n"
              << "worst_point_m: [" << fullPrecisionText(report.worst_point_m.x()) << ", "
              << fullPrecisionText(report.worst_point_m.y()) << "]\n";
    if (!args.load.empty())
      std::cout << "loaded: " << args.load << "\n";
    if (!args.save.empty())
      std::cout << "saved: " << args.save << "\n";
    return 0;
  }
  catch (const std::exception& e)
  {
    std::cerr << "scanhead_table: error: " << scanhead::toolErrorText(e) << "\n";
    return 1;
  }
}
