/// \file yaml_document.cpp
/// \brief Bounded YAML reading (see yaml_document.hpp for the limits and why).
#include "scanhead/common/yaml_document.hpp"

#include <sys/stat.h>

#include <cstdio>
#include <fstream>
#include <sstream>
#include <string_view>
#include <unordered_map>
#include <utility>
#include <vector>

#include "scanhead/common/errors.hpp"

namespace scanhead
{
namespace
{
std::string at(const std::string& source, const YAML::Mark& mark)
{
  if (mark.line < 0)
    return source;
  return source + ":" + std::to_string(mark.line + 1) + ":" + std::to_string(mark.column + 1);
}

std::string sizeText(std::size_t bytes)
{
  if (bytes >= (1u << 20) && bytes % (1u << 20) == 0)
    return std::to_string(bytes >> 20) + " MiB";
  if (bytes >= (1u << 20))
  {
    std::ostringstream out;
    out.precision(3);
    out << static_cast<double>(bytes) / (1u << 20) << " MiB";
    return out.str();
  }
  return std::to_string(bytes) + " bytes";
}

[[noreturn]] void throwTooBig(const std::string& source, std::size_t bytes, const YamlLimits& limits)
{
  const std::string size =
      bytes >= (1u << 20) ? sizeText(bytes) + " (" + std::to_string(bytes) + " bytes)" : sizeText(bytes);
  throw InputError(source + ": " + size + " is more than the " + sizeText(limits.max_bytes) + " " + limits.what +
                   " may have (YAML parsing takes ~80 bytes of memory per byte)" +
                   (limits.instead.empty() ? std::string() : ": " + limits.instead));
}

const std::string kComplexKey = "(key)";

/// One pass over the tree as a reader sees it: a shared (aliased) node is visited at every use.
class Walker
{
public:
  Walker(const std::string& source, std::size_t budget)
    : source_(source)
    , budget_(budget)
  {
  }

  void visit(const YAML::Node& node, int depth)
  {
    if (++count_ > budget_)
      throw InputError(at(source_, node.Mark()) + ": YAML aliases expand to more than " + std::to_string(budget_) +
                       " nodes (the budget of a file this size: write the repeated parts out, or split the file)");
    if (depth > kYamlMaxDepth)
      throw InputError(at(source_, node.Mark()) + ": YAML nested deeper than " + std::to_string(kYamlMaxDepth) +
                       " levels");
    if (node.IsSequence())
    {
      std::size_t index = 0;
      for (const YAML::Node& item : node)
      {
        path_.emplace_back(nullptr, index++);
        visit(item, depth + 1);
        path_.pop_back();
      }
    }
    else if (node.IsMap())
    {
      checkKeys(node);
      for (const auto& item : node)
      {
        visit(item.first, depth + 1);
        path_.emplace_back(item.first.IsScalar() ? &item.first.Scalar() : &kComplexKey, 0);
        visit(item.second, depth + 1);
        path_.pop_back();
      }
    }
  }

private:
  /// Duplicate scalar keys of one map: the second occurrence is reported with the first's line.
  void checkKeys(const YAML::Node& map)
  {
    seen_.clear();
    for (const auto& item : map)
    {
      if (!item.first.IsScalar())
        continue;
      const std::string& key = item.first.Scalar();
      const auto [it, fresh] = seen_.emplace(std::string_view(key), item.first.Mark());
      if (!fresh)
        throw InputError(at(source_, item.first.Mark()) + ": duplicate key '" + dotted(key) + "' (first at line " +
                         std::to_string(it->second.line + 1) + ")");
    }
  }

  /// The key's full name, e.g. "polylines[2].speed" (built only for an error).
  std::string dotted(const std::string& key) const
  {
    std::string name;
    for (const auto& [map_key, index] : path_)
    {
      if (map_key == nullptr)
        name += "[" + std::to_string(index) + "]";
      else
        name += (name.empty() ? "" : ".") + *map_key;
    }
    return name + (name.empty() ? "" : ".") + key;
  }

  const std::string& source_;
  std::size_t budget_;
  /// Where the walk is: a map key (its text) or a list index (nullptr, index).
  std::vector<std::pair<const std::string*, std::size_t>> path_;
  std::size_t count_ = 0;
  std::unordered_map<std::string_view, YAML::Mark> seen_;
};
}  // namespace

YamlLimits yamlJobLimits()
{
  return {8u << 20, "a YAML job",
          "give big jobs as a CLI file (scanhead_job convert --job <source> --out job.cli) or a segment path file",
          "the job file"};
}

YamlLimits yamlSettingsLimits(const std::string& what, const std::string& file)
{
  return {1u << 20, what, "settings files are a few KB; is this the right file?", file};
}

YamlLimits yamlMetricsLimits()
{
  return {16u << 20, "a metrics.yaml (before its corner list)", "is this a scanhead metrics.yaml?", "the file"};
}

std::string readYamlText(const std::string& path, const YamlLimits& limits)
{
  std::ifstream in(path, std::ios::binary);
  if (!in)
    throw InputError(path + ": cannot open " + limits.file);
  struct stat info
  {
  };
  if (::stat(path.c_str(), &info) == 0 && S_ISREG(info.st_mode) &&
      static_cast<unsigned long long>(info.st_size) > limits.max_bytes)
    throwTooBig(path, static_cast<std::size_t>(info.st_size), limits);
  // Not a regular file (a pipe): read at most one byte past the limit.
  std::string text;
  char buffer[1 << 16];
  while (in.read(buffer, sizeof buffer) || in.gcount() > 0)
  {
    text.append(buffer, static_cast<std::size_t>(in.gcount()));
    if (text.size() > limits.max_bytes)
      throwTooBig(path, text.size(), limits);
  }
  if (in.bad())
    throw InputError(path + ": read error");
  return text;
}

std::string yamlDoubleQuoted(const std::string& text)
{
  std::string out = "\"";
  for (const char c : text)
  {
    const unsigned char u = static_cast<unsigned char>(c);
    if (c == '"' || c == '\\')
      out += std::string("\\") + c;
    else if (u < 0x20 || u == 0x7f)
    {
      char hex[5];
      std::snprintf(hex, sizeof hex, "\\x%02x", u);
      out += hex;
    }
    else
      out += c;
  }
  return out + "\"";
}

YAML::Node parseYamlDocument(const std::string& text, const std::string& source, const YamlLimits& limits)
{
  if (text.size() > limits.max_bytes)
    throwTooBig(source, text.size(), limits);
  YAML::Node root;
  try
  {
    root = YAML::Load(text);
    Walker(source, kYamlNodesBase + kYamlNodesPerByte * text.size()).visit(root, 0);
  }
  catch (const YAML::Exception& e)
  {
    throw InputError(at(source, e.mark) + ": malformed YAML: " + e.msg);
  }
  return root;
}
}  // namespace scanhead
