/// \file fuzz_segment.cpp
/// \brief libFuzzer target over the segment scan-path reader: any input must either parse into a
/// well-formed job (finite points, speeds > 0 on lines, powers >= 0, dwells with one point) or
/// throw InputError. Each input is read in both units (m and mm). Build: see fuzz_smoke.sh.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>

#include "scanhead/common/errors.hpp"
#include "scanhead/job/formats/segment_path.hpp"

namespace
{
bool wellFormed(const scanhead::Job& job)
{
  for (const scanhead::Polyline& p : job.polylines)
  {
    if (!(p.power_w >= 0.0) || !std::isfinite(p.power_w) || !(p.dwell_s >= 0.0) || !std::isfinite(p.dwell_s))
      return false;
    if (p.dwell_s > 0.0 ? p.points.size() != 1
                        : (p.points.size() < 2 || !(p.speed_mps > 0.0) || !std::isfinite(p.speed_mps)))
      return false;
    for (const Eigen::Vector2d& q : p.points)
      if (!q.allFinite())
        return false;
  }
  return true;
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
  const std::string text(reinterpret_cast<const char*>(data), size);
  for (double unit_m : {1.0, 1e-3})
  {
    scanhead::SegmentReadOptions options;
    options.unit_m = unit_m;
    try
    {
      const scanhead::Job job = scanhead::parseSegmentPath(text, "fuzz.txt", options);
      if (!wellFormed(job))
        __builtin_trap();
    }
    catch (const scanhead::InputError&)
    {
    }
  }
  (void)scanhead::looksLikeSegmentPath(text);
  return 0;
}
