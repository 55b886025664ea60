/// \file study_spec.cpp
/// \brief Reading a study file (study_spec.hpp).
#include "scanhead/study/study_spec.hpp"

#include <yaml-cpp/yaml.h>

#include <filesystem>

#include "scanhead/common/errors.hpp"
#include "scanhead/common/yaml_document.hpp"

namespace scanhead
{
namespace
{
namespace fs = std::filesystem;

std::string at(const std::string& source, const YAML::Node& node)
{
  return source + ":" + std::to_string(node.Mark().line + 1);
}

/// \brief A scalar's text; a list, map or null is an error naming \p key.
std::string scalar(const YAML::Node& node, const std::string& source, const std::string& key)
{
  if (!node.IsScalar())
    throw InputError(at(source, node) + ": " + key + ": expected a value, not " +
                     (node.IsSequence() ? "a list"
                      : node.IsMap()    ? "a map"
                                        : "nothing"));
  return node.Scalar();
}

/// \brief A setting's value as scanhead_run --set takes it: a scalar, or a list of scalars as "[a, b]".
std::string settingValue(const YAML::Node& node, const std::string& source, const std::string& key)
{
  if (node.IsSequence())
  {
    std::string text = "[";
    for (std::size_t i = 0; i < node.size(); ++i)
      text += (i ? ", " : "") + scalar(node[i], source, key + "[" + std::to_string(i) + "]");
    return text + "]";
  }
  return scalar(node, source, key);
}
}  // namespace

StudySpec readStudyFile(const std::string& path)
{
  StudySpec spec;
  spec.source = path;
  spec.text = readYamlText(path, yamlSettingsLimits("a study file", "the study file"));
  const YAML::Node root = parseYamlDocument(spec.text, path, yamlSettingsLimits("a study file"));
  if (!root.IsMap())
    throw InputError(path + ":1: expected a map with jobs (and config, set, grid, plots)");
  const fs::path folder = fs::absolute(path).parent_path();
  for (const auto& item : root)
  {
    const std::string key = item.first.IsScalar() ? item.first.Scalar() : "";
    const YAML::Node value = item.second;
    if (key == "config")
    {
      const fs::path config = scalar(value, path, "config");
      spec.config_path = (config.is_absolute() ? config : folder / config).lexically_normal().string();
    }
    else if (key == "jobs")
    {
      if (!value.IsSequence() || value.size() == 0)
        throw InputError(at(path, value) + ": jobs: expected a non-empty list of job files, globs or built-in jobs");
      for (std::size_t i = 0; i < value.size(); ++i)
        spec.jobs.push_back({scalar(value[i], path, "jobs[" + std::to_string(i) + "]"), value[i].Mark().line + 1});
    }
    else if (key == "set")
    {
      if (!value.IsMap())
        throw InputError(at(path, value) + ": set: expected a map of settings (key: value)");
      for (const auto& s : value)
      {
        const std::string k = scalar(s.first, path, "set");
        spec.set.push_back(k + "=" + settingValue(s.second, path, "set." + k));
      }
    }
    else if (key == "grid")
    {
      if (!value.IsMap())
        throw InputError(at(path, value) + ": grid: expected a map of settings to lists of values");
      for (const auto& g : value)
      {
        StudyGridAxis axis;
        axis.key = scalar(g.first, path, "grid");
        axis.line = g.first.Mark().line + 1;
        const YAML::Node values = g.second;
        if (!values.IsSequence() || values.size() == 0)
          throw InputError(at(path, values) + ": grid." + axis.key + ": expected a non-empty list of values");
        for (std::size_t i = 0; i < values.size(); ++i)
          axis.values.push_back(settingValue(values[i], path, "grid." + axis.key + "[" + std::to_string(i) + "]"));
        spec.grid.push_back(std::move(axis));
      }
    }
    else if (key == "plots")
    {
      spec.plots = scalar(value, path, "plots");
      if (spec.plots != "none" && spec.plots != "summary" && spec.plots != "all")
        throw InputError(at(path, value) + ": plots: '" + spec.plots + "' is not none, summary or all");
    }
    else
      throw InputError(at(path, item.first) + ": unknown key '" + key + "' (expected: config, jobs, set, grid, plots)");
  }
  if (spec.jobs.empty())
    throw InputError(path + ":1: jobs: missing (the job files, globs or built-in jobs to run)");
  return spec;
}
}  // namespace scanhead
