/// \file python_plots.hpp
/// \brief The one place that runs the package's matplotlib scripts (scripts/plot_*.py) with the
/// system python3: the plot hook the command-line tools and the ROS nodes hand to the core.
///
/// The core only writes data files and calls a PlotHook (common/plot_hook.hpp) when they are
/// complete; it never starts a program. The results folder's plots (plotFinisher(), PlotProcess)
/// are part of the results: a script that fails or is killed throws PlotError, and the folder is
/// not published (`--plots none` runs no python at all). The other tools' charts
/// (runPythonScript, pythonPlotHook) are extras beside files already written: a failure costs the
/// chart and a warning on stderr.
#pragma once

#include <sys/types.h>

#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "scanhead/common/plot_hook.hpp"

namespace scanhead
{
/// \brief The plots asked for could not be made: names the script and how it failed.
class PlotError : public std::runtime_error
{
public:
  using std::runtime_error::runtime_error;
};

/// \brief Runs a package script (path resolved with resolvePackagePath) with /usr/bin/python3 and
/// \p arguments, each word single-quoted for the shell; its output goes to this process' stdout.
/// \param[in] what  names the plots in the warning ("scanhead: <what> skipped (...)")
/// \return false, with the warning on stderr, if the script fails
bool runPythonScript(const std::string& script, const std::vector<std::string>& arguments,
                     const std::string& what = "plots");

/// \brief A hook that runs \p script with the data folder as its only argument
/// (runPythonScript(script, {dir}, what)).
PlotHook pythonPlotHook(const std::string& script, const std::string& what = "plots");

/// \brief The results folder's hook (writeResultsFolder's finisher): scripts/plot_results.py on the
/// folder (energy_map_plot.png, speed.png, contour_error.png, corner_zoom.png, quality.png), run as
/// a PlotProcess (its own process group, cancelled on a stop request).
/// The hook throws PlotError if the script fails or is killed (the folder is then not published).
PlotHook plotFinisher();

/// \brief A plot script started before its data exists: `python3 <script> <arguments> --serve`
/// imports matplotlib while the caller computes, then reads the data folder from its stdin (and
/// starts on the plots that need no image), then the line "images" (the folder is complete), so
/// only the drawing is left once the data is written (python starts in ~0.5–1 s of CPU).
///
/// The script's stdin is one end of a socket pair (a send to a script that died reports an
/// error instead of raising SIGPIPE); its stdout and stderr go to this process' stdout, as with
/// runPythonScript. It runs in a process group of its own (a terminal's Ctrl-C reaches only this
/// process, which then cancels it). Destroying an unused PlotProcess (the run failed) ends the
/// script and its drawing processes and reaps it.
class PlotProcess
{
public:
  /// \brief Starts the script now. A failure to start is reported by plot(), like a failing script.
  PlotProcess(const std::string& script, const std::vector<std::string>& arguments, const std::string& what = "plots");
  ~PlotProcess();
  PlotProcess(const PlotProcess&) = delete;
  PlotProcess& operator=(const PlotProcess&) = delete;

  /// \brief Hands \p dir (one line) to the script without waiting: it starts on what needs no
  /// image (the writer's data_written hook). Not thread-safe: at most once, before plot().
  void begin(const std::string& dir);

  /// \brief Hands \p dir to the script (unless begin() did), then the line "images" (the
  /// folder is complete), and waits for the script to finish drawing, polling the stop request
  /// (common/stop_request) every 10 ms.
  /// \return false if the script failed, was killed or could not start (failure() says how); a
  /// second call returns false
  /// \throws StopRequested on a stop request (the script is cancelled first)
  bool plot(const std::string& dir);

  /// \brief Why plot() failed, or why the script already ended (see ended()): "<what> failed:
  /// <script> was killed by SIGKILL", "... exited with status 1 (is python3-matplotlib installed?)".
  const std::string& failure() const { return failure_; }

  /// \brief Whether the script has already ended before plot() (it failed: a served script only
  /// ends after "images"); failure() then says how. Cheap (one waitpid WNOHANG): a caller polls it
  /// while the chain runs, so a missing matplotlib stops a long run at once.
  bool ended();

  /// \brief begin() as a PlotHook.
  PlotHook beginHook();
  /// \brief Stops the script and every drawing process it started, and waits until they are gone
  /// (the results will not be published: nothing may keep writing into their folder). Idempotent.
  void cancel();

private:
  /// Records how the script ended (from its wait status) in failure_ unless it succeeded.
  bool judge(int status);

  std::string path_;  ///< the resolved script
  std::string what_;
  std::string failure_;
  pid_t pid_ = -1;      ///< -1: not started or already reaped
  pid_t group_ = -1;    ///< the script's process group, until cancel() saw it empty
  int socket_ = -1;     ///< our end of the script's stdin
  bool sent_ = true;    ///< every line so far reached the script
  bool begun_ = false;  ///< begin() was called
  bool used_ = false;   ///< plot() was called
  bool ended_ = false;  ///< the script was reaped before plot(); failure_ says how
};

/// \brief `--plots` of the tools that write results folders: none (no python at all), summary
/// (energy_map_plot.png and quality.png) or all (every plot of plot_results.py, the default).
/// \return the started scripts/plot_results.py server, or nullptr for "none"
/// \throws ConfigError if \p plots is none of the three
std::unique_ptr<PlotProcess> startResultsPlots(const std::string& plots);
}  // namespace scanhead
