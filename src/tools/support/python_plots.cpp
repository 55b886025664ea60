/// \file python_plots.cpp
#include "python_plots.hpp"

#include <cstdio>
#include <cstdlib>

#include "scanhead/common/package_path.hpp"

namespace scanhead
{
bool runPythonScript(const std::string& script, const std::vector<std::string>& arguments, const std::string& what)
{
  // Each word single-quoted, its own quotes as '\'' (labels and paths come from users).
  auto quoted = [](const std::string& word) {
    std::string out = "'";
    for (char c : word)
      out += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return out + "'";
  };
  const std::string path = resolvePackagePath(script);
  std::string command = "/usr/bin/python3 " + quoted(path);
  for (const std::string& argument : arguments)
    command += " " + quoted(argument);
  if (std::system((command + " 2>&1").c_str()) == 0)
    return true;
  std::fprintf(stderr, "scanhead: %s skipped (%s failed; is python3-matplotlib installed?)\n", what.c_str(),
               path.c_str());
  return false;
}

PlotHook pythonPlotHook(const std::string& script, const std::string& what)
{
  return [script, what](const std::string& dir) { runPythonScript(script, {dir}, what); };
}

PlotHook plotFinisher()
{
  return pythonPlotHook("scripts/plot_results.py");
}
}  // namespace scanhead
