/// \file defect_set_io.cpp
/// \brief Defect set files: reading (yaml-cpp, every error with file, line and key) and writing.
#include "scanhead/optics/defect_set_io.hpp"

#include <yaml-cpp/yaml.h>
#include <array>
#include <cstring>
#include <fstream>
#include <set>
#include <sstream>

#include "scanhead/common/errors.hpp"
#include "scanhead/common/number_text.hpp"
#include "scanhead/common/yaml_document.hpp"

namespace scanhead
{
namespace
{
constexpr std::size_t kElementCount = 8;

/// "z, a, b": the components OPT lists for element \p element (index in defectElements()).
std::string allowedComponents(std::size_t element)
{
  std::string list;
  for (const DefectComponent& c : defectComponents())
  {
    if (std::strcmp(c.element, defectElements()[element]) == 0)
      list += (list.empty() ? "" : ", ") + std::string(1, c.component);
  }
  return list;
}

std::string elementList()
{
  std::string list;
  for (const char* key : defectElements())
    list += (list.empty() ? "" : ", ") + std::string(key);
  return list;
}

/// Index in the 30 of (element, component), or kDefectCount.
std::size_t componentIndex(std::size_t element, const std::string& component)
{
  for (std::size_t k = 0; k < kDefectCount; ++k)
  {
    const DefectComponent& c = defectComponents()[k];
    if (std::strcmp(c.element, defectElements()[element]) == 0 && component.size() == 1 && component[0] == c.component)
      return k;
  }
  return kDefectCount;
}

/// Whether \p text is valid UTF-8 without control characters (U+0000–U+001F, U+007F).
bool printableUtf8(const std::string& text)
{
  for (std::size_t i = 0; i < text.size();)
  {
    const unsigned char c = static_cast<unsigned char>(text[i]);
    if (c < 0x80)
    {
      if (c < 0x20 || c == 0x7f)
        return false;
      ++i;
      continue;
    }
    // Lead byte: 2, 3 or 4 bytes; no overlong forms (C0, C1, E0 < A0, F0 < 90), nothing past U+10FFFF.
    const std::size_t n = c >= 0xC2 && c <= 0xDF ? 2 : c >= 0xE0 && c <= 0xEF ? 3 : c >= 0xF0 && c <= 0xF4 ? 4 : 0;
    if (n == 0 || i + n > text.size())
      return false;
    const unsigned char c1 = static_cast<unsigned char>(text[i + 1]);
    if ((c == 0xE0 && c1 < 0xA0) || (c == 0xED && c1 > 0x9F) || (c == 0xF0 && c1 < 0x90) || (c == 0xF4 && c1 > 0x8F))
      return false;
    for (std::size_t k = 1; k < n; ++k)
      if ((static_cast<unsigned char>(text[i + k]) & 0xC0) != 0x80)
        return false;
    i += n;
  }
  return true;
}

std::string where(const std::string& path, const YAML::Node& node)
{
  return path + ":" + std::to_string(node.Mark().line + 1);
}

std::string fileStem(const std::string& path)
{
  const std::size_t slash = path.find_last_of('/');
  std::string name = slash == std::string::npos ? path : path.substr(slash + 1);
  const std::size_t dot = name.find_last_of('.');
  return dot == std::string::npos || dot == 0 ? name : name.substr(0, dot);
}
}  // namespace

DefectSet loadDefectSet(const std::string& path)
{
  return parseDefectSet(readYamlText(path, yamlSettingsLimits("a defect set file", "the defect set file")), path);
}

DefectSet parseDefectSet(const std::string& text, const std::string& path)
{
  const YAML::Node root = parseYamlDocument(text, path, yamlSettingsLimits("a defect set file"));

  DefectSet set;
  set.name = fileStem(path);
  if (root.IsNull())
    return set;  // empty file: the nominal machine
  const std::string format =
      " (a defect set maps elements to {component: value}, mm and mrad, e.g. "
      "'mirror_x: {z: -0.025, a: -0.062, b: 0.029}'; elements: " +
      elementList() + "; and name)";
  if (!root.IsMap())
    throw InputError(where(path, root) + ": not a map" + format);
  std::set<std::string> seen;
  std::array<bool, kDefectCount> given{};
  for (const auto& entry : root)
  {
    const std::string key = entry.first.IsScalar() ? entry.first.Scalar() : std::string("(not a scalar)");
    if (!seen.insert(key).second)
      throw InputError(where(path, entry.first) + ": duplicate key '" + key + "'");
    if (key == "name")
    {
      if (!entry.second.IsScalar() || entry.second.Scalar().empty())
        throw InputError(where(path, entry.second) + ": name must be a non-empty string");
      // A label for reports and file names: control characters and invalid UTF-8 (found by
      // fuzz_defect_set: a NUL cut the written name short, stray bytes were re-encoded) are refused.
      if (!printableUtf8(entry.second.Scalar()))
        throw InputError(where(path, entry.second) +
                         ": name must be printable UTF-8 text (it has a control character or an invalid byte)");
      set.name = entry.second.Scalar();
      continue;
    }
    std::size_t element = kElementCount;
    for (std::size_t k = 0; k < kElementCount; ++k)
    {
      if (key == defectElements()[k])
        element = k;
    }
    if (element == kElementCount)
      throw InputError(where(path, entry.first) + ": unknown element '" + key + "' (elements: " + elementList() +
                       "; and name)");
    const YAML::Node& components = entry.second;
    if (components.IsNull())
      continue;  // `window_1:` with nothing: zero
    if (!components.IsMap())
      throw InputError(where(path, components) + ": " + key + " must be a map {component: value} of " +
                       allowedComponents(element));
    for (const auto& field : components)
    {
      const std::string component = field.first.IsScalar() ? field.first.Scalar() : std::string("(not a scalar)");
      const std::string label = key + "." + component;
      const std::size_t index = componentIndex(element, component);
      if (index == kDefectCount)
        throw InputError(where(path, field.first) + ": unknown component '" + label + "' (" + key + " has " +
                         allowedComponents(element) + ": OPT table 1)");
      if (given[index])
        throw InputError(where(path, field.first) + ": duplicate key '" + label + "'");
      given[index] = true;
      const std::string value_text = field.second.IsScalar() ? field.second.Scalar() : std::string("(not a scalar)");
      double value = 0.0;
      const NumberText parsed = parseNumber(value_text, value);
      if (parsed != NumberText::Ok)
        throw InputError(where(path, field.second) + ": " + label + " is " +
                         (parsed == NumberText::NotFinite ? "not finite" : "not a number") + " ('" + value_text +
                         "'; " + (defectComponents()[index].rotation() ? "mrad" : "mm") + ")");
      set.values[index] = value;
    }
  }
  return set;
}

std::string defectSetToYaml(const DefectSet& set)
{
  YAML::Emitter name;
  name << set.name;
  std::string out =
      "# scanhead defect set (docs/defects.md): positions in mm (x, y, z), orientations in mrad (a, b, c about x, y, "
      "z)\n"
      "name: " +
      std::string(name.c_str(), name.size()) + "\n";
  for (std::size_t element = 0; element < kElementCount; ++element)
  {
    std::string line = std::string(defectElements()[element]) + ":";
    line.resize(12, ' ');
    line += "{";
    bool first = true;
    for (std::size_t k = 0; k < kDefectCount; ++k)
    {
      const DefectComponent& c = defectComponents()[k];
      if (std::strcmp(c.element, defectElements()[element]) != 0)
        continue;
      line += std::string(first ? "" : ", ") + c.component + ": " + shortestText(set.values[k]);
      first = false;
    }
    out += line + "}\n";
  }
  return out;
}
}  // namespace scanhead
