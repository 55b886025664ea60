/// \file laser_settling.cpp
/// \brief Early and late laser-on samples around each laser window.
#include "scanhead/metrics/laser_settling.hpp"

#include <algorithm>

#include "scanhead/common/config_check.hpp"
#include "scanhead/common/segment_distance.hpp"

namespace scanhead
{
namespace
{
/// A spot that has not met its mark after this many segments is far off anyway: bounds the scan.
constexpr std::size_t kMaxEarlySegments = 64;

}  // namespace

LaserSettlingCheck::LaserSettlingCheck(const NcProgram& program, double gate_shift_s, double filter_delay_s,
                                       double tolerance_m)
  : gate_shift_s_(gate_shift_s)
  , filter_delay_s_(filter_delay_s)
  , tolerance_m_(tolerance_m)
{
  requireSetting(tolerance_m > 0.0, "energy.laser_path_tolerance_m", "> 0", tolerance_m);
  const auto& segments = program.timeline.segments();
  for (const LaserWindow& w : program.gate.windows())
  {
    if (!(w.off_s > w.on_s) || w.first_segment >= w.end_segment)
      continue;
    const std::size_t first = segments_.size();
    for (std::size_t k = w.first_segment; k < w.end_segment; ++k)
      segments_.push_back({segments[k].start_m, segments[k].end_m, segments[k].t_start_s});
    windows_.push_back({w.on_s, w.off_s, w.burst_end_s, first, segments_.size()});
  }
}

void LaserSettlingCheck::process(const SpotChunk& chunk)
{
  for (std::size_t k = 0; k < chunk.samples.size(); ++k)
  {
    const SpotSample& s = chunk.samples[k];
    if (!(s.power_w > 0.0))
      continue;
    const double t_s = static_cast<double>(chunk.first_index + k) * chunk.period_s;
    const double command_s = t_s - gate_shift_s_;
    while (current_ < windows_.size() && command_s >= windows_[current_].off_s)
      ++current_;
    if (current_ >= windows_.size() || command_s < windows_[current_].on_s)
      continue;  // not in a window: a stream the program did not make (or a rounding edge)
    const Window& w = windows_[current_];
    const double energy = s.power_w * chunk.period_s;
    if (arrived_window_ != current_)
    {
      // Distance to the burst's path up to where the filtered path is (at least its first segment).
      const double path_s = t_s - filter_delay_s_;
      double d = pointSegmentDistance(s.actual, segments_[w.first].a, segments_[w.first].b);
      const std::size_t scan_end = std::min(w.end, w.first + kMaxEarlySegments);
      for (std::size_t k = w.first + 1; k < scan_end && segments_[k].t_start_s <= path_s; ++k)
        d = std::min(d, pointSegmentDistance(s.actual, segments_[k].a, segments_[k].b));
      if (d <= tolerance_m_)
      {
        arrived_window_ = current_;
      }
      else
      {
        counts_.early_samples += 1;
        counts_.early_energy_j += energy;
        counts_.worst_distance_m = std::max(counts_.worst_distance_m, d);
        continue;
      }
    }
    if (t_s - filter_delay_s_ >= w.burst_end_s)
    {
      const double d = pointSegmentDistance(s.actual, segments_[w.end - 1].a, segments_[w.end - 1].b);
      if (d > tolerance_m_)
      {
        counts_.late_samples += 1;
        counts_.late_energy_j += energy;
        counts_.worst_distance_m = std::max(counts_.worst_distance_m, d);
      }
    }
  }
}
}  // namespace scanhead
