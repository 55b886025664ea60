/// \file python_plots.hpp
/// \brief The one place that runs the package's matplotlib scripts (scripts/plot_*.py) with the
/// system python3: the plot hook the command-line tools and the ROS nodes hand to the core.
///
/// The core only writes data files and calls a PlotHook (common/plot_hook.hpp) when they are
/// complete; it never starts a program. Plots are never essential: a script that fails (most
/// often: python3-matplotlib not installed) costs the plots and a warning on stderr, never the
/// results.
#pragma once

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
}  // namespace scanhead
