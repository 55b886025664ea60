/// \file study_cases.hpp
/// \brief A study's cases: every job (a layered file: every layer) × every combination of the grid, each with the
/// settings it runs with and an identity that changes when, and only when, its job or its settings change.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "scanhead/study/study_spec.hpp"

namespace scanhead
{
struct StudyCase
{
  std::string id;   ///< folder name: <job>[_layerK][_<key>-<value>…]_<hash>, the hash of the job file's content, job,
                    ///< layer and settings
  std::string job;  ///< scanhead_run --job (a file's absolute path, or a built-in spec)
  std::string label;  ///< the job as a person reads it: the file name or the spec
  int layer = -1;     ///< the layer of a layered file (cam.layer), -1: the job is not split by layer
  std::vector<std::pair<std::string, std::string>> grid;  ///< this case's grid values, in the grid's order
  std::string config_yaml;  ///< every setting of the case (what the results' config.yaml holds)
};

/// \brief The cases of \p spec with the base settings of \p config_path and then, in order, the study's set:, its
/// grid values, \p extra_sets (the command line's --set) and, for layered files, cam.layer.
/// A job file that cannot be read still becomes one case (its run fails and keeps the reader's error).
/// \throws InputError naming the study file, line and key: a glob matching no file, a missing file, a grid key or
/// set: key the config does not have, a combination of settings that is not valid
std::vector<StudyCase> planStudyCases(const StudySpec& spec, const std::string& config_path,
                                      const std::vector<std::string>& extra_sets);

/// \brief 64-bit FNV-1a of \p text continued from \p hash (the case identity; stable across machines).
std::uint64_t fnv1a(const std::string& text, std::uint64_t hash = 14695981039346656037ull);

/// \brief fnv1a() of the bytes of the file \p path, read 1 MiB at a time (of "" if it cannot be read).
std::uint64_t fileFnv1a(const std::string& path);
}  // namespace scanhead
