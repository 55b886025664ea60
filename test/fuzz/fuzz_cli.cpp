/// \file fuzz_cli.cpp
/// \brief libFuzzer target over the CLI reader (ASCII and binary): any input must either parse
/// into a well-formed job or throw InputError; a parsed job written back as ASCII CLI+ must read
/// back with the same marks. Build: see fuzz_smoke.sh.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>

#include "scanhead/common/errors.hpp"
#include "scanhead/job/formats/cli_format.hpp"

namespace
{
bool wellFormed(const scanhead::Job& job)
{
  for (const scanhead::Polyline& p : job.polylines)
  {
    if (p.points.size() < 2 || !(p.speed_mps > 0.0) || !std::isfinite(p.speed_mps) || !(p.power_w >= 0.0) ||
        !std::isfinite(p.power_w) || p.dwell_s != 0.0)
      return false;
    for (const Eigen::Vector2d& q : p.points)
      if (!q.allFinite())
        return false;
  }
  return true;
}

std::size_t markCount(const scanhead::Job& job)
{
  std::size_t n = 0;
  for (const scanhead::Polyline& p : job.polylines)
    n += p.type == scanhead::PolylineType::Mark;
  return n;
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  scanhead::CliReadOptions options;
  options.layer = -1;  // every layer is built
  scanhead::Job job;
  try
  {
    job = scanhead::parseCli(bytes, "fuzz.cli", options);
  }
  catch (const scanhead::InputError&)
  {
    return 0;  // a clear rejection is the expected outcome for most inputs
  }
  if (!wellFormed(job))
    __builtin_trap();
  std::string text;
  try
  {
    text = scanhead::writeCliAsciiPlus(job, 1.0);
  }
  catch (const scanhead::InputError&)
  {
    return 0;  // a coordinate too large for the chosen units
  }
  const scanhead::Job back = scanhead::parseCli(text, "fuzz_rewritten.cli", options);  // must not throw
  if (markCount(back) != markCount(job) || !wellFormed(back))
    __builtin_trap();
  return 0;
}
