// scanhead_run: the whole virtual machine in one process (batch runner).
#include <signal.h>
#include <unistd.h>

#include <csignal>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include "process_memory.hpp"
#include "scanhead/chain/batch_chain.hpp"
#include "scanhead/chain/config_io.hpp"
#include "scanhead/chain/results_writer.hpp"
#include "scanhead/common/errors.hpp"
#include "scanhead/common/stop_request.hpp"
#include "scanhead/job/formats/job_io.hpp"
#include "scanhead/job/job_files.hpp"
#include "scanhead/job/job_stats.hpp"
#include "scanhead/metrics/metrics_report.hpp"
#include "support/command_line.hpp"
#include "support/python_plots.hpp"
#include "support/tool_errors.hpp"

#include <chrono>

namespace
{
struct Arguments
{
  std::string job = "corner";
  std::string out;
  scanhead::ConfigArguments config;
  bool quiet = false;
  std::string plots = "all";
};

/// \brief The options into \p a. \return false after --help
bool parse(int argc, char** argv, Arguments& a)
{
  CLI::App app("The whole virtual machine in one process (batch runner).", "scanhead_run");
  scanhead::configureApp(app);
  app.add_option("--job", a.job,
                 scanhead::jobFormatsHelp() +
                     "\n(default: corner); CLI files: --set cam.layer=N (-1: all); segment files: --set cam.units=mm")
      ->type_name("JOB");
  app.add_option("--out", a.out,
                 "results folder to write (metrics.yaml, energy map, plots, job statistics); default: results/<job>")
      ->type_name("DIR");
  a.config.addTo(app, "nc.fir_t1_s=300e-6");
  app.add_option("--plots", a.plots,
                 "plots in the results folder: all (default), summary (energy_map_plot.png and quality.png) or "
                 "none (no python started)")
      ->type_name("none|summary|all")
      ->transform(scanhead::check::oneOf({"none", "summary", "all"}));
  app.add_flag("--quiet", a.quiet, "no job statistics, progress or metrics table; the run line only");
  return scanhead::parseCommandLine(app, argc, argv);
}

/// SIGINT, SIGTERM, SIGHUP: the first asks the run to stop (the chain's progress callback, the
/// results writer and the plot wait see it and unwind, removing the staging folder and the plot
/// process); a second one ends the process at once (the next run on the folder removes what is
/// left). Only async-signal-safe calls here: an atomic store, write, sigaction, raise.
extern "C" void onStopSignal(int signal)
{
  if (scanhead::stopRequest() != 0)
  {
    struct sigaction default_action = {};
    default_action.sa_handler = SIG_DFL;
    sigaction(signal, &default_action, nullptr);
    raise(signal);
    return;
  }
  scanhead::requestStop(signal);
  static const char message[] =
      "\nscanhead_run: stopping, removing what this run wrote (signal again to end at once)\n";
  const ssize_t ignored = write(STDERR_FILENO, message, sizeof(message) - 1);
  (void)ignored;
}

void installStopHandlers()
{
  struct sigaction action = {};
  action.sa_handler = onStopSignal;
  sigemptyset(&action.sa_mask);
  action.sa_flags = 0;  // no SA_RESTART: a blocking call returns EINTR and its caller checks the request
  for (int signal : {SIGINT, SIGTERM, SIGHUP})
  {
    // A signal ignored on entry stays ignored (nohup; a background job of a shell without job
    // control ignores SIGINT), as the shell conventions want.
    struct sigaction previous = {};
    if (sigaction(signal, nullptr, &previous) == 0 && previous.sa_handler != SIG_IGN)
      sigaction(signal, &action, nullptr);
  }
}

/// Appended to a failure of the results: what became of the folder.
std::string folderState(const std::string& out)
{
  std::error_code ec;
  return std::filesystem::exists(out, ec) ? "the previous results in " + out + " are unchanged"
                                          : "nothing was written to " + out;
}

constexpr const char* kNoPlotsHint = "; --plots none writes the results without starting python";
}  // namespace

int main(int argc, char** argv)
{
  using namespace scanhead;
  installStopHandlers();
  std::string out;
  try
  {
    Arguments args;
    if (!parse(argc, argv, args))
      return 0;
    const ChainConfig config = args.config.load();
    const OpticalModel optics = loadOpticalModel(config.optics);
    Job job = loadJob(args.job, config.cam);
    validateScanJob(job, config.optics.field_half_width_m);
    // The plan refuses a job beyond limits.* (or physically impossible) before anything is started.
    const RunPlan plan = planRun(config, job, optics);
    enforceRunLimits(plan, config.limits, physicalMemoryBytes());
    throwIfStopRequested();  // a signal while the job was read and planned
    out = args.out.empty() ? "results/" + job.name : args.out;
    // The folder is ours before anything is computed: a second run on it fails now, naming this one.
    std::vector<std::string> stale;
    const FolderLock lock = lockResultsFolder(out, &stale);
    for (const std::string& path : stale)
      std::fprintf(stderr, "scanhead_run: removed %s, left by a run that was killed\n", path.c_str());
    throwIfStopRequested();
    if (!args.quiet)
    {
      const JobStats stats = computeJobStats(job, config.nc.implicit_jump_speed_mps);
      std::printf("job %s: %zu marks (%.3f mm), %zu jumps (%.3f mm), ideal time %.3f ms, laser energy %.4g J\n",
                  job.name.c_str(), stats.mark_count, stats.mark_length_m * 1e3, stats.jump_count,
                  stats.jump_length_m * 1e3, stats.ideal_time_s * 1e3, stats.laser_on_energy_j);
      std::printf("%s", runPlanText(plan).c_str());
    }

    // Python imports matplotlib while the chain runs; only the drawing is left at the end.
    const std::unique_ptr<PlotProcess> plotter = startResultsPlots(args.plots);
    BatchChain chain(config, optics);
    int last_percent = -1;
    const bool to_terminal = ::isatty(STDERR_FILENO) != 0;
    const auto start = std::chrono::steady_clock::now();
    std::uint64_t plotter_checked = 0;
    const RunMetrics metrics = chain.run(job, plan, [&](std::uint64_t done, std::uint64_t total) {
      throwIfStopRequested();
      // A plot script that already ended has failed (no matplotlib?): stop now, not after the run.
      if (plotter && done - plotter_checked >= 65536)
      {
        plotter_checked = done;
        if (plotter->ended())
          throw PlotError(plotter->failure() + kNoPlotsHint);
      }
      const int percent = static_cast<int>(100 * done / total);
      // A terminal: one line rewritten each percent; a log (not a TTY): one line every 10 %.
      const bool show = to_terminal ? percent != last_percent : percent / 10 != last_percent / 10;
      if (!args.quiet && total > 200000 && show)
      {
        // Progress with the real-time factor so far and the time left at that pace.
        const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        const double machine = static_cast<double>(done) * config.nc.period_s;
        const double left = done > 0 ? wall * static_cast<double>(total - done) / static_cast<double>(done) : 0.0;
        std::fprintf(stderr, "%s%3d %% of %llu samples (%.1f s of machine time), %.1fx real time, %.0f s left%s",
                     to_terminal ? "\r" : "", percent, static_cast<unsigned long long>(total),
                     static_cast<double>(total) * config.nc.period_s, wall > 0.0 ? machine / wall : 0.0, left,
                     to_terminal ? "   " : "\n");
        if (to_terminal && done == total)
          std::fprintf(stderr, "\n");
      }
      last_percent = percent;
    });
    throwIfStopRequested();
    if (!args.quiet && metrics.samples > 200000)
      std::fprintf(stderr, "measuring the layer and writing %s ...\n", out.c_str());
    const auto chain_end = std::chrono::steady_clock::now();
    double plots_s = 0.0;
    PlotHook plots;
    if (plotter)
      plots = [&](const std::string& dir) {
        const auto plots_start = std::chrono::steady_clock::now();
        if (!plotter->plot(dir))
          throw PlotError(plotter->failure() + kNoPlotsHint);
        plots_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - plots_start).count();
      };
    try
    {
      writeResultsFolder(lock, metrics, chain.energy(), config, job, plots, plotter ? plotter->beginHook() : PlotHook(),
                         [&plotter] {
                           if (plotter)
                             plotter->cancel();
                         });
    }
    catch (const StopRequested&)
    {
      throw;
    }
    catch (const std::exception& e)
    {
      throw InputError(std::string(e.what()) + "; " + folderState(out));
    }
    const auto end = std::chrono::steady_clock::now();
    const double wall = std::chrono::duration<double>(end - start).count();
    const double chain_s = std::chrono::duration<double>(chain_end - start).count();
    const double results_s = std::chrono::duration<double>(end - chain_end).count() - plots_s;
    if (!args.quiet)
      std::cout << metricsTable(metrics) << ncLimitsLine(chain.nc().stats(), config.nc);
    std::printf(
        "run: %.2f s wall (chain %.2f s, results %.2f s, plots %.2f s) for %.4g s of machine time "
        "(%.3gx real time), process peak memory %.0f MiB\n",
        wall, chain_s, results_s, plots_s, metrics.duration_s, metrics.duration_s / wall,
        processPeakResidentBytes() / 1048576.0);
    if (!args.quiet)
      std::cout << "results written to " << out << "/\n";
    return 0;
  }
  catch (const StopRequested& stop)
  {
    // Everything this run started is gone by now (the unwinding removed it).
    std::cerr << "scanhead_run: " << stop.what() << "; " << (out.empty() ? "nothing written" : folderState(out))
              << "\n";
    // Die of the signal, so a calling shell or make sees an interrupted child and stops too.
    std::fflush(nullptr);
    std::signal(stop.signal(), SIG_DFL);
    std::raise(stop.signal());
    return 128 + stop.signal();
  }
  catch (const std::exception& e)
  {
    std::cerr << "scanhead_run: error: " << scanhead::toolErrorText(e) << "\n";
    return 1;
  }
}
