/// \file python_plots.hpp
/// \brief The one place that runs the package's matplotlib scripts (scripts/plot_*.py) with the
/// system python3: the plot hook the command-line tools and the ROS nodes hand to the core.
///
/// The core only writes data files and calls a PlotHook (common/plot_hook.hpp) when they are
/// complete; it never starts a program. Plots are never essential: a script that fails (most
/// often: python3-matplotlib not installed) costs the plots and a warning on stderr, never the
/// results.
#pragma once

#include <sys/types.h>

#include <memory>
#include <string>
#include <vector>

#include "scanhead/common/plot_hook.hpp"

namespace scanhead
{
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
/// folder (energy_map_plot.png, speed.png, contour_error.png, corner_zoom.png, quality.png).
PlotHook plotFinisher();

/// \brief A plot script started before its data exists: `python3 <script> <arguments> --serve`
/// imports matplotlib while the caller computes, then reads the data folder from its stdin (and
/// starts on the plots that need no image), then the line "images" (the folder is complete), so
/// only the drawing is left once the data is written (python starts in ~0.5–1 s of CPU).
///
/// The script's stdin is one end of a socket pair (a send to a script that died reports an
/// error instead of raising SIGPIPE); its stdout and stderr go to this process' stdout, as with
/// runPythonScript. Destroying an unused PlotProcess (the run failed) ends the script with
/// SIGTERM and reaps it.
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
  /// folder is complete), and waits for the script to finish drawing.
  /// \return false, with the warning of runPythonScript on stderr, if the script failed or
  /// could not start; a second call returns false without a warning.
  bool plot(const std::string& dir);

  /// \brief plot() as a PlotHook; the PlotProcess must outlive the hook's use.
  PlotHook hook();
  /// \brief begin() as a PlotHook.
  PlotHook beginHook();
  /// \brief Stops the script and every drawing process it started, and waits for the script (the
  /// results will not be published: nothing may keep writing into their folder). Idempotent.
  void cancel();

private:
  std::string path_;  ///< the resolved script
  std::string what_;
  pid_t pid_ = -1;      ///< -1: not started or already reaped
  int socket_ = -1;     ///< our end of the script's stdin
  bool sent_ = true;    ///< every line so far reached the script
  bool begun_ = false;  ///< begin() was called
  bool used_ = false;   ///< plot() was called
};

/// \brief `--plots` of the tools that write results folders: none (no python at all), summary
/// (energy_map_plot.png and quality.png) or all (every plot of plot_results.py, the default).
/// \return the started scripts/plot_results.py server, or nullptr for "none"
/// \throws ConfigError if \p plots is none of the three
std::unique_ptr<PlotProcess> startResultsPlots(const std::string& plots);
}  // namespace scanhead
