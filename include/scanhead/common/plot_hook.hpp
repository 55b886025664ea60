/// \file plot_hook.hpp
/// \brief The callback a core function calls once its data files are written: "the data is in
/// this folder, make the plots now".
///
/// The core never runs programs itself (no std::system, no popen): plotting is the caller's
/// business. The command-line tools and the ROS nodes pass the hook of
/// src/tools/support/python_plots.hpp, which runs the package's matplotlib scripts; tests and
/// library users pass nothing and get the data files only.
#pragma once

#include <functional>
#include <string>

namespace scanhead
{
/// \brief Called with the folder that holds the freshly written data files. An empty hook means
/// "no plots". A hook should not throw for a missing plotting tool: the plots are never essential.
using PlotHook = std::function<void(const std::string& dir)>;
}  // namespace scanhead
