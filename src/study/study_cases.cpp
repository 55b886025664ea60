/// \file study_cases.cpp
/// \brief Expanding a study into cases (study_cases.hpp).
#include "scanhead/study/study_cases.hpp"

#include <glob.h>

#include <algorithm>
#include <filesystem>
#include <fstream>

#include "scanhead/chain/config_io.hpp"
#include "scanhead/common/errors.hpp"
#include "scanhead/job/generators/builtin_jobs.hpp"
#include "scanhead/job/job_files.hpp"

namespace scanhead
{
namespace
{
namespace fs = std::filesystem;

/// \brief Letters, digits, '.', '-' kept; anything else one '_'; at most \p max characters.
std::string slug(const std::string& text, std::size_t max)
{
  std::string out;
  for (const char c : text)
  {
    const bool keep = std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '-';
    if (keep)
      out += c;
    else if (out.empty() || out.back() != '_')
      out += '_';
  }
  while (!out.empty() && out.back() == '_')
    out.pop_back();
  return out.substr(0, max);
}

std::string hex(std::uint64_t value, int digits)
{
  static const char kDigits[] = "0123456789abcdef";
  std::string out(static_cast<std::size_t>(digits), '0');
  for (int i = digits - 1; i >= 0; --i, value >>= 4)
    out[static_cast<std::size_t>(i)] = kDigits[value & 15u];
  return out;
}

/// \brief The files a jobs: entry names (a glob or a path, relative to the study file's folder), sorted.
std::vector<std::string> jobFiles(const StudyJobEntry& entry, const StudySpec& spec, std::size_t index)
{
  const std::string where = spec.source + ":" + std::to_string(entry.line) + ": jobs[" + std::to_string(index) + "]";
  const fs::path folder = fs::absolute(spec.source).parent_path();
  const fs::path pattern = fs::path(entry.text).is_absolute() ? fs::path(entry.text) : folder / entry.text;
  const bool is_glob = entry.text.find_first_of("*?[") != std::string::npos;
  if (!is_glob)
  {
    if (!fs::is_regular_file(pattern))
      throw InputError(where + ": '" + entry.text + "' is neither a file (looked for " + pattern.string() +
                       ") nor a built-in job");
    return {pattern.lexically_normal().string()};
  }
  glob_t found{};
  const int status = glob(pattern.c_str(), 0, nullptr, &found);
  std::vector<std::string> files;
  for (std::size_t i = 0; status == 0 && i < found.gl_pathc; ++i)
    if (fs::is_regular_file(found.gl_pathv[i]))
      files.push_back(fs::path(found.gl_pathv[i]).lexically_normal().string());
  globfree(&found);
  if (files.empty())
    throw InputError(where + ": '" + entry.text + "' matches no file (looked in " + pattern.parent_path().string() +
                     ")");
  std::sort(files.begin(), files.end());
  return files;
}

/// \brief The settings' key of an assignment "key=value".
std::string keyOf(const std::string& assignment)
{
  return assignment.substr(0, assignment.find('='));
}

/// \brief Every combination of the grid's values (the last axis fastest); one empty combination without a grid.
std::vector<std::vector<std::pair<std::string, std::string>>> combinations(const std::vector<StudyGridAxis>& grid)
{
  std::vector<std::vector<std::pair<std::string, std::string>>> all{{}};
  for (const StudyGridAxis& axis : grid)
  {
    std::vector<std::vector<std::pair<std::string, std::string>>> next;
    for (const auto& partial : all)
      for (const std::string& value : axis.values)
      {
        auto combo = partial;
        combo.emplace_back(axis.key, value);
        next.push_back(std::move(combo));
      }
    all = std::move(next);
  }
  return all;
}
}  // namespace

std::uint64_t fnv1a(const std::string& text, std::uint64_t hash)
{
  for (const char c : text)
  {
    hash ^= static_cast<unsigned char>(c);
    hash *= 1099511628211ull;
  }
  return hash;
}

std::uint64_t fileFnv1a(const std::string& path)
{
  std::ifstream in(path, std::ios::binary);
  std::uint64_t hash = fnv1a("");
  std::string block(1 << 20, '\0');  // 1 MiB at a time: a build file of any size hashes in bounded memory
  while (in)
  {
    in.read(&block[0], static_cast<std::streamsize>(block.size()));
    block.resize(static_cast<std::size_t>(in.gcount()));
    hash = fnv1a(block, hash);
    block.resize(1 << 20);
  }
  return hash;
}

std::vector<StudyCase> planStudyCases(const StudySpec& spec, const std::string& config_path,
                                      const std::vector<std::string>& extra_sets)
{
  // The keys first, each named where it was written.
  const std::vector<std::string> known = knownConfigKeys();
  auto isKnown = [&](const std::string& key) { return std::binary_search(known.begin(), known.end(), key); };
  for (const std::string& s : spec.set)
    if (!isKnown(keyOf(s)))
      throw InputError(spec.source + ": set." + keyOf(s) + ": not a setting of the config (see config/scanhead.yaml)");
  for (const StudyGridAxis& axis : spec.grid)
    if (!isKnown(axis.key))
      throw InputError(spec.source + ":" + std::to_string(axis.line) + ": grid." + axis.key +
                       ": not a setting of the config (see config/scanhead.yaml)");
  bool layer_set = false;
  for (const std::string& s : spec.set)
    layer_set = layer_set || keyOf(s) == "cam.layer";
  for (const std::string& s : extra_sets)
    layer_set = layer_set || keyOf(s) == "cam.layer";
  for (const StudyGridAxis& axis : spec.grid)
    layer_set = layer_set || axis.key == "cam.layer";

  // The settings of each combination, checked once.
  struct Combination
  {
    std::vector<std::pair<std::string, std::string>> grid;
    std::vector<std::string> overrides;
    ChainConfig config;
  };
  std::vector<Combination> combos;
  for (auto& grid : combinations(spec.grid))
  {
    Combination c;
    c.overrides = spec.set;
    for (const auto& [key, value] : grid)
      c.overrides.push_back(key + "=" + value);
    c.overrides.insert(c.overrides.end(), extra_sets.begin(), extra_sets.end());
    try
    {
      c.config = loadChainConfig(config_path, c.overrides);
    }
    catch (const std::exception& e)
    {
      std::string values;
      for (const auto& [key, value] : grid)
        values += (values.empty() ? " (grid: " : ", ") + key + "=" + value;
      throw InputError(spec.source + ": settings" + (values.empty() ? "" : values + ")") + ": " + e.what());
    }
    c.grid = std::move(grid);
    combos.push_back(std::move(c));
  }

  std::vector<StudyCase> cases;
  for (std::size_t j = 0; j < spec.jobs.size(); ++j)
  {
    const StudyJobEntry& entry = spec.jobs[j];
    const bool builtin = isBuiltinJobName(entry.text.substr(0, entry.text.find(':')));
    const std::vector<std::string> files = builtin ? std::vector<std::string>{entry.text} : jobFiles(entry, spec, j);
    for (const std::string& job : files)
    {
      const std::uint64_t content = builtin ? fnv1a("") : fileFnv1a(job);  // once per file, not per case
      // One case per layer of a layered file (unless the study sets cam.layer itself).
      std::size_t layers = 1;
      bool layered = false;
      if (!builtin && !layer_set)
      {
        try
        {
          CamConfig cam = combos.front().config.cam;
          cam.layer = 0;
          const Job first = loadJob(job, cam);
          layered = first.file.layers > 1;
          layers = first.file.layers;
        }
        catch (const std::exception&)
        {
          // The case runs and fails with the reader's message, kept with the case.
        }
      }
      const std::string stem = builtin ? slug(job, 48) : slug(fs::path(job).stem().string(), 48);
      for (std::size_t layer = 0; layer < layers; ++layer)
        for (const Combination& combo : combos)
        {
          StudyCase c;
          c.job = job;
          c.label = builtin ? job : fs::path(job).filename().string();
          c.layer = layered ? static_cast<int>(layer) : -1;
          c.grid = combo.grid;
          ChainConfig config = combo.config;
          if (layered)
            config.cam.layer = static_cast<int>(layer);
          c.config_yaml = chainConfigToYaml(config);
          std::string name = stem;
          if (layered)
          {
            const std::string k = std::to_string(layer);
            name += "_layer" + std::string(k.size() < 4 ? 4 - k.size() : 0, '0') + k;
          }
          for (const auto& [key, value] : c.grid)
            name += "_" + slug(key.substr(key.rfind('.') + 1), 24) + "-" + slug(value, 24);
          // stream.threads is left out: any thread count gives bit-identical results, and the local backend
          // chooses it per case.
          ChainConfig identity = config;
          identity.stream.threads = 1;
          const std::uint64_t hash =
              fnv1a(chainConfigToYaml(identity), fnv1a(job + "\n" + std::to_string(c.layer) + "\n", content));
          c.id = name + "_" + hex(hash, 12);
          cases.push_back(std::move(c));
        }
    }
  }
  return cases;
}
}  // namespace scanhead
