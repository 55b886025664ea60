/// \file study_spec.hpp
/// \brief A study file: the jobs, the settings common to every case and the grid of settings to sweep.
///
/// \code
/// config: my_machine.yaml           # optional: the base settings (default: the package's config/scanhead.yaml)
/// jobs:                             # files, globs (relative to this file) and built-in jobs
///   - build/layers_*.cli            # a multi-layer CLI or segment file: one case per layer
///   - squares:rows=1,columns=2
/// set:                              # settings of every case (scanhead_run --set)
///   recipe.preset: thesis1
/// grid:                             # every combination is a case
///   servo.position_controller: [pd, hinf]
///   recipe.preset: [thesis1, thesis2]
/// plots: none                       # results plots of each case: none (default), summary, all
/// \endcode
/// Every key and value is checked before any case runs: unknown keys, a glob that matches no file, a grid key the
/// config does not have, a grid axis without values, a setting no case could run with (messages name the study
/// file, its line and the key).
#pragma once

#include <string>
#include <vector>

namespace scanhead
{
/// \brief One swept setting: key and its values, in the file's order.
struct StudyGridAxis
{
  std::string key;
  std::vector<std::string> values;
  int line = 0;  ///< line of the key in the study file
};

/// \brief One jobs: entry as written, with its line.
struct StudyJobEntry
{
  std::string text;
  int line = 0;
};

struct StudySpec
{
  std::string source;       ///< the study file
  std::string text;         ///< its content as read (copied into the study folder)
  std::string config_path;  ///< base config, absolute; "" for the package's default
  std::vector<StudyJobEntry> jobs;
  std::vector<std::string> set;  ///< "key=value", in the file's order
  std::vector<StudyGridAxis> grid;
  std::string plots = "none";
};

/// \brief Reads and checks the study file's structure (keys, types, globs are expanded later).
/// \throws InputError "file:line: key: what is wrong"
StudySpec readStudyFile(const std::string& path);
}  // namespace scanhead
