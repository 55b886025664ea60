// scanhead_job: scan jobs on their own — statistics, picture, conversion, reader speed.
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "scanhead/chain/batch_chain.hpp"
#include "scanhead/chain/config_io.hpp"
#include "scanhead/common/errors.hpp"
#include "scanhead/common/text_file.hpp"
#include "scanhead/job/formats/cli_format.hpp"
#include "scanhead/job/formats/job_io.hpp"
#include "scanhead/job/formats/segment_path.hpp"
#include "scanhead/job/generators/builtin_jobs.hpp"
#include "scanhead/job/job_files.hpp"
#include "scanhead/job/job_stats.hpp"
#include "scanhead/report/job_picture.hpp"
#include "support/command_line.hpp"
#include "support/tool_errors.hpp"

namespace
{
struct Arguments
{
  std::string command, job, out;
  scanhead::ConfigArguments config;
  int size = 1600;
  long lines = 20000;
  bool binary = false;
  double units_mm = 1e-3;
};

/// \brief The command and its options into \p a. \return false after --help
bool parse(int argc, char** argv, Arguments& a)
{
  CLI::App app("Scan jobs on their own: statistics, picture, conversion, reader speed.", "scanhead_job");
  scanhead::configureApp(app);
  app.footer(
      "JOB: a .yaml job, a .cli file (ASCII or binary), a segment scan-path file, or a built-in job\n"
      "(corner, hatch, squares; see scanhead_run --help). --set cam.layer=N and cam.units=mm|m apply.");
  a.config.addTo(app, "cam.layer=2");
  const auto job = [&](CLI::App* command) { command->add_option("JOB", a.job, "the job (see below)")->required(); };
  double size = a.size, lines = static_cast<double>(a.lines);
  job(app.add_subcommand("stats",
                         "statistics on the ideal timeline (YAML): lengths, counts, times, energy;\n"
                         "for the built-in squares job also the time of each square"));
  CLI::App* picture = app.add_subcommand("picture", "the job drawn: marks dark blue, jumps grey dashed");
  job(picture);
  picture->add_option("--out", a.out, "the picture to write")->type_name("F.png")->required();
  picture->add_option("--size", size, "picture size in pixels (default 1600)")
      ->type_name("PX")
      ->transform(scanhead::check::positiveNumber());
  CLI::App* convert = app.add_subcommand("convert", "write the job as .yaml or .cli (ASCII; --binary for binary CLI)");
  job(convert);
  convert->add_option("--out", a.out, "the file to write: .yaml, .yml or .cli")->type_name("F")->required();
  convert->add_flag("--binary", a.binary, "binary CLI instead of ASCII");
  convert->add_option("--units-mm", a.units_mm, "CLI unit in mm (default 0.001)")
      ->type_name("U")
      ->transform(scanhead::check::positiveNumber());
  CLI::App* bench = app.add_subcommand("bench", "reading speed (MB/s) of each reader on a large generated job");
  bench->add_option("--lines", lines, "hatch lines of the generated job (default 20000)")
      ->type_name("N")
      ->transform(scanhead::check::positiveNumber());
  app.require_subcommand(0, 1);  // one command; a missing one is named by parseCommandLine
  if (!scanhead::parseCommandLine(app, argc, argv))
    return false;
  a.command = app.get_subcommands().front()->get_name();
  a.size = static_cast<int>(size);
  a.lines = static_cast<long>(lines);
  return true;
}

bool endsWith(const std::string& text, const std::string& suffix)
{
  return text.size() >= suffix.size() && text.compare(text.size() - suffix.size(), suffix.size(), suffix) == 0;
}

/// The same job as a segment scan-path file (mode 0 lines, mode 1 dwells), for the reader benchmark.
std::string segmentText(const scanhead::Job& job)
{
  std::ostringstream rows;
  std::size_t count = 0;
  char line[160];
  for (const auto& p : job.polylines)
    for (std::size_t k = 0; k < p.points.size(); ++k)
    {
      const bool first = count == 0;
      const double coefficient = p.type == scanhead::PolylineType::Mark && k > 0 ? 1.0 : 0.0;
      std::snprintf(line, sizeof line, "%d %.9g %.9g 0 %g %.9g\n", first ? 1 : 0, p.points[k].x(), p.points[k].y(),
                    coefficient, first ? 1e-6 : p.speed_mps);
      rows << line;
      ++count;
    }
  return "Number of path segments\n" + std::to_string(count) + "\nMode x y z pmod param\n" + rows.str();
}

template <class Read>
void timeReader(const char* name, const std::string& bytes, Read&& read)
{
  using Clock = std::chrono::steady_clock;
  read(bytes);  // warm-up
  int runs = 0;
  const auto start = Clock::now();
  double elapsed = 0.0;
  std::size_t polylines = 0;
  while (elapsed < 1.0 || runs < 3)
  {
    polylines = read(bytes).polylines.size();
    ++runs;
    elapsed = std::chrono::duration<double>(Clock::now() - start).count();
  }
  std::printf("%-22s %8.1f MB in %5.3f s per read: %7.1f MB/s (%zu polylines, %d runs)\n", name, bytes.size() / 1e6,
              elapsed / runs, bytes.size() / 1e6 / (elapsed / runs), polylines, runs);
}

void bench(long lines)
{
  using namespace scanhead;
  const double size = 0.3;  // a 300 mm square hatched with `lines` lines
  const Job job = builtinJob("hatch:size=" + std::to_string(size) + ",spacing=" + std::to_string(size / lines));
  timeReader("YAML job", scanJobToYaml(job), [](const std::string& b) { return parseScanJobYaml(b, "bench.yaml"); });
  CliReadOptions cli;
  cli.layer = 0;
  timeReader("CLI ASCII", writeCliAscii(job, 1e-3),
             [&](const std::string& b) { return parseCli(b, "bench.cli", cli); });
  timeReader("CLI binary", writeCliBinary(job, 1e-3),
             [&](const std::string& b) { return parseCli(b, "bench.cli", cli); });
  SegmentReadOptions seg;
  timeReader("segment path", segmentText(job),
             [&](const std::string& b) { return parseSegmentPath(b, "bench.txt", seg); });
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
    if (args.command == "bench")
    {
      bench(args.lines);
      return 0;
    }
    const ChainConfig config = args.config.load();
    if (args.command == "stats")
    {
      if (args.job.substr(0, args.job.find(':')) == "squares")
      {
        const SquareJob squares = builtinSquareJob(args.job);
        std::cout << jobStatsYaml(
            computeJobStats(squares.job, config.nc.implicit_jump_speed_mps, squares.square_of_polyline));
      }
      else
        std::cout << jobStatsYaml(computeJobStats(loadJob(args.job, config.cam), config.nc.implicit_jump_speed_mps));
      return 0;
    }
    const Job job = loadJob(args.job, config.cam);
    if (args.command == "picture")
      writeJobPicture(args.out, job, args.size);
    else if (endsWith(args.out, ".cli"))
      writeTextFile(args.out, args.binary ? writeCliBinary(job, args.units_mm) : writeCliAscii(job, args.units_mm));
    else if (endsWith(args.out, ".yaml") || endsWith(args.out, ".yml"))
      writeTextFile(args.out, scanJobToYaml(job));
    else
      throw ConfigError("--out must end in .yaml or .cli (got '" + args.out + "')");
    std::cout << args.command << ": " << job.name << " -> " << args.out << "\n";
    return 0;
  }
  catch (const std::exception& e)
  {
    std::cerr << "scanhead_job: error: " << scanhead::toolErrorText(e) << "\n";
    return 1;
  }
}
