/// \file trace_recorder.hpp
/// \brief Keeps a decimated copy of the spot stream for plots, in bounded memory.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "scanhead/common/chunk.hpp"

namespace scanhead
{
struct TraceRow
{
  std::uint64_t index = 0;  ///< sample index
  SpotSample spot;
  double setpoint_speed_mps = 0.0;  ///< |Δ setpoint| / Ts over the previous sample
  double actual_speed_mps = 0.0;
};

class TraceRecorder
{
public:
  /// \param[in] total_samples samples the job will produce; \param[in] max_rows kept at most
  TraceRecorder(std::uint64_t total_samples, std::size_t max_rows);
  void process(const SpotChunk& chunk);
  const std::vector<TraceRow>& rows() const { return rows_; }
  std::uint64_t stride() const { return stride_; }
  /// \brief CSV with a header line: t_s, setpoint and actual x/y [m], speeds [m/s], power [W].
  std::string csv(double period_s) const;

private:
  std::uint64_t stride_;
  std::vector<TraceRow> rows_;
  bool has_prev_ = false;
  SpotSample prev_;
};
}  // namespace scanhead
