/// \file fuzz_yaml_job.cpp
/// \brief libFuzzer target over the YAML job reader (parseScanJobYaml, through parseYamlDocument):
/// any input must either parse into a well-formed job or throw InputError (malformed YAML, a
/// duplicate key, aliases expanding past the budget, a bad field); a parsed job written back with
/// scanJobToYaml must read back to the same job, bit for bit. Build: see fuzz_smoke.sh.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>

#include "scanhead/common/errors.hpp"
#include "scanhead/job/formats/job_io.hpp"

namespace
{
bool wellFormed(const scanhead::Job& job)
{
  if (job.polylines.empty())
    return false;
  for (const scanhead::Polyline& p : job.polylines)
  {
    const bool dwell = p.dwell_s > 0.0;
    if (dwell ? p.points.size() != 1 : p.points.size() < 2)
      return false;
    if (!std::isfinite(p.speed_mps) || !std::isfinite(p.power_w) || !std::isfinite(p.dwell_s) || p.dwell_s < 0.0)
      return false;
    for (const Eigen::Vector2d& q : p.points)
      if (!q.allFinite())
        return false;
  }
  return true;
}

bool same(const scanhead::Job& a, const scanhead::Job& b)
{
  if (a.name != b.name || a.polylines.size() != b.polylines.size())
    return false;
  for (std::size_t i = 0; i < a.polylines.size(); ++i)
  {
    const scanhead::Polyline& p = a.polylines[i];
    const scanhead::Polyline& q = b.polylines[i];
    // The writer gives a role to marks only (a jump's role is read and ignored).
    const bool role_differs = p.type == scanhead::PolylineType::Mark && p.role != q.role;
    if (p.type != q.type || role_differs || p.power_w != q.power_w || p.dwell_s != q.dwell_s ||
        p.speed_mps != q.speed_mps || p.points != q.points)
      return false;
  }
  return true;
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
  const std::string text(reinterpret_cast<const char*>(data), size);
  scanhead::Job job;
  try
  {
    job = scanhead::parseScanJobYaml(text, "fuzz.yaml");
  }
  catch (const scanhead::InputError&)
  {
    return 0;  // a clear rejection
  }
  if (!wellFormed(job))
    __builtin_trap();
  const scanhead::Job back = scanhead::parseScanJobYaml(scanhead::scanJobToYaml(job), "fuzz_rewritten.yaml");
  if (!same(job, back))
    __builtin_trap();
  return 0;
}
