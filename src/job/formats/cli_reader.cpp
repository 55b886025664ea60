/// \file cli_reader.cpp
/// \brief parseCli / readCliFile / looksLikeCli: header, then ASCII or binary geometry.
#include <fstream>

#include "cli_internal.hpp"
#include "scanhead/common/config_check.hpp"
#include "scanhead/common/errors.hpp"

namespace scanhead
{
void CliReadOptions::validate() const
{
  if (layer < -1)
    failSetting("cam.layer", ">= -1 (-1: all layers)", layer);
  requireSetting(mark_speed_mps > 0.0, "cam.mark_speed_mps", "> 0", mark_speed_mps);
  requireSetting(jump_speed_mps > 0.0, "cam.jump_speed_mps", "> 0", jump_speed_mps);
  requireSetting(mark_power_w >= 0.0, "cam.mark_power_w", ">= 0", mark_power_w);
}

Job parseCli(const std::string& bytes, const std::string& source, const CliReadOptions& options)
{
  options.validate();
  const cli::Header header = cli::parseHeader(bytes, source);
  cli::JobBuilder builder(options, header.units_mm * 1e-3);
  if (header.binary)
    cli::parseBinaryGeometry(bytes, header, source, builder);
  else
    cli::parseAsciiGeometry(bytes, header, source, builder);
  return builder.finish(source, header.declared_layers);
}

Job readCliFile(const std::string& path, const CliReadOptions& options)
{
  std::ifstream in(path, std::ios::binary);
  if (!in)
    throw InputError(path + ": cannot open the CLI file");
  in.seekg(0, std::ios::end);
  const std::streamoff size = in.tellg();
  in.seekg(0, std::ios::beg);
  std::string bytes;
  if (size > 0)
  {
    bytes.resize(static_cast<std::size_t>(size));
    in.read(&bytes[0], size);
  }
  if (!in)
    throw InputError(path + ": read error");
  return parseCli(bytes, path, options);
}

bool looksLikeCli(const std::string& first_bytes)
{
  const std::size_t limit = first_bytes.size() < 1024 ? first_bytes.size() : 1024;
  return first_bytes.substr(0, limit).find("$$HEADERSTART") != std::string::npos;
}
}  // namespace scanhead
