// scanhead_study: many cases (the layers of a build, a grid of settings) run, resumed and summarised.
#include <signal.h>
#include <unistd.h>

#include <filesystem>
#include <iostream>
#include <string>
#include <thread>

#include "scanhead/common/errors.hpp"
#include "scanhead/common/folder_lock.hpp"
#include "scanhead/common/package_path.hpp"
#include "scanhead/common/stop_request.hpp"
#include "scanhead/common/text_file.hpp"
#include "scanhead/study/study_cases.hpp"
#include "scanhead/study/study_estimate.hpp"
#include "scanhead/study/study_folder.hpp"
#include "scanhead/study/study_summary.hpp"
#include "support/command_line.hpp"
#include "support/python_plots.hpp"
#include "support/slurm_backend.hpp"
#include "support/study_runner.hpp"
#include "support/tool_errors.hpp"

namespace
{
namespace fs = std::filesystem;
using namespace scanhead;

/// SIGINT, SIGTERM, SIGHUP: stop starting cases, let the running ones stop (they get the signal too), keep them
/// pending. Without SA_RESTART, so that the wait for a case returns at once.
void installStopHandler()
{
  struct sigaction action = {};
  action.sa_handler = [](int signal) { requestStop(signal); };
  sigemptyset(&action.sa_mask);
  action.sa_flags = 0;
  for (const int s : {SIGINT, SIGTERM, SIGHUP})
    sigaction(s, &action, nullptr);
}

struct Counts
{
  std::size_t done = 0, failed = 0, pending = 0;
};

Counts countOf(const std::vector<CaseRecord>& records)
{
  Counts c;
  for (const CaseRecord& r : records)
    (r.state == CaseState::Done ? c.done : r.state == CaseState::Failed ? c.failed : c.pending) += 1;
  return c;
}

/// \brief summary.csv, summary.md, the plots of the figures across layers and grid values and summary.html (the
/// page with them); \p plotter: the plot
/// script started with the cases (it has imported matplotlib meanwhile), else it is started now.
void collect(const std::string& dir, PlotProcess* plotter = nullptr)
{
  const std::vector<CaseRecord> records = readStudyCases(dir);
  std::string html_body;
  const std::size_t with_figures = writeStudySummary(dir, records, &html_body);
  if (with_figures > 0 && plotter != nullptr)
  {
    if (!plotter->plot(dir))
      std::cerr << "scanhead_study: study plots skipped (" << plotter->failure() << ")\n";
  }
  else if (with_figures > 0)
    runPythonScript("scripts/plot_study.py", {(fs::path(dir) / "summary.csv").string(), dir}, "study plots");
  writeStudySummaryPage(dir, html_body);  // after the plots: it embeds them
  const Counts c = countOf(records);
  std::cout << "study " << dir << ": " << records.size() << " cases, " << c.done << " done, " << c.failed << " failed, "
            << c.pending << " pending; summary in " << (fs::path(dir) / "summary.html").string() << "\n";
}
}  // namespace

int main(int argc, char** argv)
{
  try
  {
    CLI::App app("Runs many cases (the layers of a build, a grid of settings), resumes them and summarises them.",
                 "scanhead_study");
    configureApp(app);
    app.require_subcommand(1);

    std::string study_file, out, backend = "local", plots, partition, time_limit;
    unsigned workers = 0;  // 0: the cores
    unsigned max_running = 0, cpus_per_task = 2;
    bool retry_failed = false, dry_run = false, wait = false;
    std::string config_path;
    std::vector<std::string> overrides;
    CLI::App* run = app.add_subcommand("run", "run the study's pending cases (finished ones are kept)");
    run->add_option("STUDY", study_file, "the study file (jobs:, set:, grid:; see the README)")->required();
    run->add_option("--out", out, "the study folder")->required()->type_name("DIR");
    run->add_option("--backend", backend, "local (default: worker processes here) or slurm (one job array)")
        ->check(CLI::IsMember({"local", "slurm"}));
    run->add_option("--workers", workers,
                    "local: cases at once (default: the cores); while cases wait each runs on one thread, the last "
                    "ones on stream.threads (the same results)")
        ->transform(check::integerAtLeast(1));
    run->add_option("--set", overrides, "a setting of every case, after the study's set: and grid (repeatable)")
        ->type_name("KEY=VALUE")
        ->allow_extra_args(false);
    run->add_option("--config", config_path, "base settings (default: the study's config:, else the package's)")
        ->type_name("FILE");
    run->add_option("--plots", plots, "results plots of each case: none, summary, all (default: the study's plots:)")
        ->check(CLI::IsMember({"none", "summary", "all"}));
    run->add_flag("--retry-failed", retry_failed, "run the failed cases again too");
    run->add_flag("--dry-run", dry_run, "slurm: print the batch script, submit nothing; local: list the cases");
    run->add_option("--max-running", max_running, "slurm: array tasks running at once (%M; default: no limit)");
    run->add_option("--cpus-per-task", cpus_per_task, "slurm: CPUs per case (default 2: the chain's two threads)")
        ->transform(check::integerAtLeast(1));
    run->add_option("--partition", partition, "slurm: partition (default: the cluster's)");
    run->add_option("--time", time_limit, "slurm: time limit per case (e.g. 30:00)");
    run->add_flag("--wait", wait, "slurm: return when the array and its collection have ended");

    std::string dir;
    CLI::App* status = app.add_subcommand("status", "how many cases are done, failed, pending; the failures' errors");
    status->add_option("DIR", dir, "the study folder")->required();
    CLI::App* collect_cmd = app.add_subcommand("collect", "write summary.csv, summary.md, the study plots and summary.html");
    collect_cmd->add_option("DIR", dir, "the study folder")->required();
    std::size_t index = 0;
    CLI::App* run_case = app.add_subcommand("run-case", "run one case of a study folder (a Slurm array task)");
    run_case->add_option("DIR", dir, "the study folder")->required();
    run_case->add_option("INDEX", index, "the case's index in cases.tsv")->required();
    if (!parseCommandLine(app, argc, argv))
      return 0;
    installStopHandler();

    if (*status)
    {
      const std::vector<CaseRecord> records = readStudyCases(dir);
      const Counts c = countOf(records);
      std::cout << dir << ": " << records.size() << " cases: " << c.done << " done, " << c.failed << " failed, "
                << c.pending << " pending\n";
      for (const CaseRecord& r : records)
        if (r.state == CaseState::Failed)
          std::cout << "  failed " << r.id << " (exit " << r.exit_code << "): " << r.error << "\n";
      return 0;
    }
    if (*collect_cmd)
    {
      collect(dir);
      return 0;
    }
    StudyRunOptions options;
    options.scanhead_run = siblingExecutable("scanhead_run");
    if (*run_case)
    {
      const std::vector<CaseRecord> records = readStudyCases(dir);
      if (index >= records.size())
        throw InputError(dir + "/cases.tsv: no case " + std::to_string(index) + " (the study has " +
                         std::to_string(records.size()) + ")");
      if (records[index].state == CaseState::Done)
        return 0;  // a resubmitted array task: finished already
      options.plots = readFileOrEmpty((fs::path(dir) / "plots").string());
      if (options.plots.empty())
        options.plots = "none";
      return runStudyCase(dir, records[index], options) ? 0 : 1;
    }

    // run
    const StudySpec spec = readStudyFile(study_file);
    const std::string base = !config_path.empty()        ? config_path
                             : !spec.config_path.empty() ? spec.config_path
                                                         : resolvePackagePath("config/scanhead.yaml");
    const std::vector<StudyCase> cases = planStudyCases(spec, base, overrides);
    options.plots = plots.empty() ? spec.plots : plots;
    if (workers == 0)
      workers = std::max(1u, std::thread::hardware_concurrency());
    options.workers = workers;
    options.progress_tty = ::isatty(STDERR_FILENO) != 0;
    // One study process on a folder at a time (Slurm tasks lock their cases' folders through scanhead_run).
    const FolderLock lock(out);
    writeStudyPlan(out, spec.text, cases);
    writeFileWhole((fs::path(out) / "plots").string(), options.plots);
    const std::vector<CaseRecord> records = readStudyCases(out);
    std::vector<std::size_t> todo;
    for (const CaseRecord& r : records)
      if (r.state == CaseState::Pending || (retry_failed && r.state == CaseState::Failed))
        todo.push_back(r.index);
    const Counts c = countOf(records);
    // Said before anything runs, so that a study of hours is known as such (run plans, ×0.5–2).
    const StudyEstimate estimate = estimateStudy(cases, todo);
    const double per_worker = backend == "local" ? estimate.wall_time_s / std::max(1u, workers) : estimate.wall_time_s;
    if (!todo.empty())
      std::cerr << "scanhead_study: " << todo.size() << " cases to run: " << durationText(estimate.machine_time_s)
                << " of machine time, estimated " << durationText(0.5 * per_worker) << " to "
                << durationText(2.0 * per_worker) << (backend == "local" ? " here" : " of CPU on the cluster")
                << " (the chains; run plans)"
                << (estimate.unplanned > 0 ? ", " + std::to_string(estimate.unplanned) + " cases unreadable" : "")
                << (0.5 * per_worker > 3600.0 ? ": hours; consider --backend slurm or fewer cases" : "") << "\n";
    std::cerr << "scanhead_study: " << records.size() << " cases: " << c.done << " done, " << c.failed << " failed"
              << (c.failed > 0 && !retry_failed ? " (kept; --retry-failed runs them again)" : "") << ", " << todo.size()
              << " to run (" << (backend == "local" ? "local, " + std::to_string(workers) + " at once" : backend)
              << ")\n";
    const SlurmOptions slurm{fs::absolute(siblingExecutable("scanhead_study")).string(),
                             max_running,
                             cpus_per_task,
                             partition,
                             time_limit,
                             wait};
    if (dry_run)
    {
      if (backend == "slurm")
        std::cout << slurmArrayScript(out, todo, slurm);
      else
        for (const std::size_t k : todo)
          std::cout << records[k].id << "\t" << records[k].job << "\n";
      return 0;
    }
    if (backend == "slurm")
    {
      if (todo.empty())
      {
        collect(out);
        return 0;
      }
      submitSlurmStudy(out, todo, slurm);
      if (wait)
        collect(out);
      return 0;
    }
    PlotProcess plotter("scripts/plot_study.py", {}, "study plots");  // imports matplotlib beside the cases
    const std::size_t failed = runStudyLocally(out, records, todo, options);
    if (stopRequest() != 0)
    {
      std::cerr << "scanhead_study: stopped (" << signalName(stopRequest())
                << "); finished cases are kept, run the same command to go on\n";
      return 128 + stopRequest();
    }
    collect(out, &plotter);
    // Exit 0 only when every case is done (failures kept from earlier runs count too).
    return failed == 0 && countOf(readStudyCases(out)).failed == 0 ? 0 : 1;
  }
  catch (const std::exception& e)
  {
    std::cerr << "scanhead_study: error: " << toolErrorText(e) << "\n";
    return 1;
  }
}
