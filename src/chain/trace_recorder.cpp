#include "scanhead/chain/trace_recorder.hpp"

#include <algorithm>
#include <cstdio>

namespace scanhead
{
TraceRecorder::TraceRecorder(std::uint64_t total_samples, std::size_t max_rows)
  : stride_(std::max<std::uint64_t>(1, (total_samples + max_rows - 1) / std::max<std::size_t>(1, max_rows)))
{
  rows_.reserve(std::min<std::uint64_t>(total_samples / stride_ + 1, max_rows + 1));
}

void TraceRecorder::process(const SpotChunk& chunk)
{
  for (std::size_t k = 0; k < chunk.samples.size(); ++k)
  {
    const SpotSample& s = chunk.samples[k];
    const std::uint64_t index = chunk.first_index + k;
    if (index % stride_ == 0)
    {
      TraceRow row;
      row.index = index;
      row.spot = s;
      if (has_prev_)
      {
        row.setpoint_speed_mps = (s.setpoint - prev_.setpoint).norm() / chunk.period_s;
        row.actual_speed_mps = (s.actual - prev_.actual).norm() / chunk.period_s;
      }
      rows_.push_back(row);
    }
    prev_ = s;
    has_prev_ = true;
  }
}

std::string TraceRecorder::csv(double period_s) const
{
  std::string out = "t_s,setpoint_x_m,setpoint_y_m,actual_x_m,actual_y_m,setpoint_speed_mps,actual_speed_mps,power_w\n";
  char line[256];
  for (const TraceRow& r : rows_)
  {
    std::snprintf(line, sizeof line, "%.9g,%.12g,%.12g,%.12g,%.12g,%.9g,%.9g,%.6g\n",
                  static_cast<double>(r.index) * period_s, r.spot.setpoint.x(), r.spot.setpoint.y(), r.spot.actual.x(),
                  r.spot.actual.y(), r.setpoint_speed_mps, r.actual_speed_mps, r.spot.power_w);
    out += line;
  }
  return out;
}
}  // namespace scanhead
