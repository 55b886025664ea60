#include "scanhead/chain/trace_recorder.hpp"

#include <algorithm>
#include <charconv>

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
  out.reserve(out.size() + rows_.size() * 160);
  // "%.<digits>g" per column: std::to_chars in general format with a precision writes the same
  // characters (C++17 [charconv.to.chars]: as printf in the C locale), without snprintf's cost.
  char line[256];
  auto put = [&line](char* at, double value, int digits, char end) {
    at = std::to_chars(at, line + sizeof line - 1, value, std::chars_format::general, digits).ptr;
    *at = end;
    return at + 1;
  };
  for (const TraceRow& r : rows_)
  {
    char* at = put(line, static_cast<double>(r.index) * period_s, 9, ',');
    at = put(at, r.spot.setpoint.x(), 12, ',');
    at = put(at, r.spot.setpoint.y(), 12, ',');
    at = put(at, r.spot.actual.x(), 12, ',');
    at = put(at, r.spot.actual.y(), 12, ',');
    at = put(at, r.setpoint_speed_mps, 9, ',');
    at = put(at, r.actual_speed_mps, 9, ',');
    at = put(at, r.spot.power_w, 6, '\n');
    out.append(line, at);
  }
  return out;
}
}  // namespace scanhead
