/// \file config_io.hpp
/// \brief Reads the run configuration from YAML, with `section.key=value` overrides.
///
/// The YAML mirrors ChainConfig, keys are the struct members (see config/scanhead.yaml):
/// \code
/// stream: {chunk_samples: 1000, window_chunks: 16}
/// nc:     {period_s: 1.0e-5, fir_t1_s: 260.0e-6, fir_t2_s: 125.0e-6, ...}
/// servo:  {model: closed_loop_3rd_order, x: {bandwidth_hz: 1300, ...}, y: {...}, kc_over_jeq: 1.2e5}
/// optics: {urdf_path: urdf/scanhead.urdf, window_thickness_m: 3.0e-3, ...}
/// energy: {spot_diameter_m: 70.0e-6, pixel_m: 5.0e-6, ...}
/// \endcode
/// Missing keys keep their defaults; unknown keys, non-numeric values, NaN and infinities are
/// errors that name the file, line and key.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "scanhead/chain/chain_config.hpp"

namespace scanhead
{
/// \brief A scalar setting and where it was given ("file:line" or "--set").
struct ConfigValue
{
  std::string text;
  std::string where;
};

/// \brief Settings by dotted key, e.g. "nc.fir_t1_s".
using FlatConfig = std::map<std::string, ConfigValue>;

/// \brief Flattens a YAML text (maps of maps of scalars). \throws InputError naming \p source and the line
FlatConfig flattenYaml(const std::string& yaml_text, const std::string& source);

/// \brief Applies "section.key=value" onto \p flat (the key must be a known setting). \throws ConfigError
void applyOverride(FlatConfig& flat, const std::string& assignment);

/// \brief Builds and validates the config from flat settings. \throws ConfigError naming key and origin
ChainConfig chainConfigFromFlat(const FlatConfig& flat);

/// \brief Reads \p path (empty: defaults only), applies \p overrides in order, validates.
ChainConfig loadChainConfig(const std::string& path, const std::vector<std::string>& overrides);

/// \brief The whole config as YAML, every value at full precision (round-trips bit-exactly).
std::string chainConfigToYaml(const ChainConfig& config);

/// \brief The settings that differ between two configs written by chainConfigToYaml, as
/// "key: <value in a> vs <value in b>", sorted by key, for the keys under \p sections (e.g. "nc"). Identical texts
/// differ in nothing (they are not read).
/// \throws InputError if the texts differ and one is not such YAML
std::vector<std::string> differingSettings(const std::string& yaml_a, const std::string& yaml_b,
                                           const std::vector<std::string>& sections);

/// \brief Every known key, sorted (for help texts and error messages).
std::vector<std::string> knownConfigKeys();
}  // namespace scanhead
