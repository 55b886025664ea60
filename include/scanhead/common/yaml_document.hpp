/// \file yaml_document.hpp
/// \brief The one way the project reads YAML: bounded text size, bounded expansion, no duplicate keys.
///
/// yaml-cpp alone accepts three things a reader must not (measured on yaml-cpp 0.7):
/// - any size: parsing takes ~80 bytes of memory and ~0.4 µs per byte of text (an 89 MB job: 7.3 GB,
///   33 s), so the text is refused above a per-reader limit *before* it is read or parsed;
/// - aliases: `*a` shares the anchored node, so a 538 KB "billion laughs" file parses to a small tree
///   that a reader walking it expands to 7.6 GB. The tree is walked once, counting every node at every
///   use (an alias counts its whole subtree each time), and refused as soon as the count passes
///   kYamlNodesBase + kYamlNodesPerByte × bytes (a file without aliases has fewer nodes than bytes);
/// - duplicate mapping keys: kept both, so `node["k"]` returned the first and a flattening loop the
///   last. The second occurrence is an error naming its line and column.
/// Nesting is bounded too (kYamlMaxDepth; yaml-cpp's own parser stops at depth 2000).
#pragma once

#include <yaml-cpp/yaml.h>

#include <cstddef>
#include <string>

namespace scanhead
{
/// Expanded-node budget of a document of b bytes: kYamlNodesBase + kYamlNodesPerByte × b.
constexpr std::size_t kYamlNodesBase = 10000;
constexpr std::size_t kYamlNodesPerByte = 2;
/// Deepest nesting of maps and lists accepted (the project's files nest at most 6 deep).
constexpr int kYamlMaxDepth = 64;

/// What a reader accepts: the text's size limit and, for the size error, what the file is and what to
/// do instead (e.g. "a YAML job" / "give big jobs as CLI or segment path files").
struct YamlLimits
{
  std::size_t max_bytes = 1u << 20;
  std::string what = "a YAML file";
  std::string instead;
  std::string file = "the file";  ///< in "<path>: cannot open <file>"
};

/// Limits of the project's readers (every shipped and test file is ≥ 50× below its limit).
/// Jobs: 8 MiB (measured: an 8.3 MB job of 102 000 polylines reads in 3.7 s and 727 MiB with scanhead_job
/// stats on a loaded 2-core machine; the reader benchmark's default job is 5.8 MB); bigger jobs are CLI or
/// segment path files.
YamlLimits yamlJobLimits();
/// Settings files (chain config, KM0 config, defect sets): 1 MiB (config/scanhead.yaml is 14 KB).
/// \p what: e.g. "a config file"; \p file: e.g. "the config file" (for "cannot open").
YamlLimits yamlSettingsLimits(const std::string& what, const std::string& file = "the file");
/// A results folder's metrics.yaml up to its corner list: 16 MiB.
YamlLimits yamlMetricsLimits();

/// \brief Reads \p path whole for parsing with parseYamlDocument, refusing it before reading when it
/// is larger than limits.max_bytes.
/// \throws InputError "<path>: cannot open <file>" or "<path>: N bytes is more than the M bytes …"
std::string readYamlText(const std::string& path, const YamlLimits& limits);

/// \brief Parses \p text (named \p source in errors) with yaml-cpp and checks it: size, expansion
/// (aliases counted at every use), depth and duplicate keys.
/// \throws InputError "<source>:<line>:<column>: …" for malformed YAML, a duplicate key, too deep a
/// nesting or aliases expanding past the budget; "<source>: N bytes is more than …" for the size.
YAML::Node parseYamlDocument(const std::string& text, const std::string& source, const YamlLimits& limits);

/// \brief \p text as a YAML double-quoted scalar, quotes included: backslash, quote and control
/// characters escaped, everything else as is (so ordinary names and paths are written unchanged).
std::string yamlDoubleQuoted(const std::string& text);
}  // namespace scanhead
