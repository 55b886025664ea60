/// \file fuzz_config.cpp
/// \brief libFuzzer target over the run configuration readers: the input is a YAML config text,
/// optionally followed by a line "--set" and one `section.key=value` override per line. Any input
/// must either give a validated ChainConfig or throw InputError / ConfigError; a config that reads
/// must write (chainConfigToYaml) and read back to the same text (settings round-trip bit-exactly).
/// Build: see fuzz_smoke.sh.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "scanhead/chain/config_io.hpp"
#include "scanhead/common/errors.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
  const std::string input(reinterpret_cast<const char*>(data), size);
  const std::string separator = "\n--set\n";
  const std::size_t split = input.find(separator);
  const std::string yaml = input.substr(0, split);
  std::vector<std::string> overrides;
  if (split != std::string::npos)
  {
    std::size_t start = split + separator.size();
    while (start <= input.size())
    {
      const std::size_t end = input.find('\n', start);
      overrides.push_back(input.substr(start, end == std::string::npos ? std::string::npos : end - start));
      if (end == std::string::npos)
        break;
      start = end + 1;
    }
  }
  scanhead::ChainConfig config;
  try
  {
    scanhead::FlatConfig flat = scanhead::flattenYaml(yaml, "fuzz.yaml");
    for (const std::string& assignment : overrides)
      scanhead::applyOverride(flat, assignment);
    config = scanhead::chainConfigFromFlat(flat);
  }
  catch (const scanhead::InputError&)
  {
    return 0;
  }
  catch (const scanhead::ConfigError&)
  {
    return 0;
  }
  const std::string text = scanhead::chainConfigToYaml(config);
  const scanhead::ChainConfig back = scanhead::chainConfigFromFlat(scanhead::flattenYaml(text, "fuzz_rewritten.yaml"));
  if (scanhead::chainConfigToYaml(back) != text)
    __builtin_trap();
  return 0;
}
