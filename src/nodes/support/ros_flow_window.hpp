/// \file ros_flow_window.hpp
/// \brief Producer side of the flow control: at most a window of samples beyond the last
/// acknowledgement of the last stage (energy/ack) is in flight.
#pragma once

#include <scanhead/ChunkAck.h>

#include <cstdint>

namespace scanhead
{
class FlowWindow
{
public:
  /// \brief A new job: nothing sent, nothing acknowledged.
  void start(std::uint32_t job_id, std::uint64_t window_samples)
  {
    job_id_ = job_id;
    window_ = window_samples;
    sent_ = acked_ = 0;
  }
  bool canSend() const { return sent_ < acked_ + window_; }
  void sent(std::uint64_t end_index) { sent_ = end_index; }
  /// \return true if the acknowledgement moved the window (then send more)
  bool onAck(const ChunkAck& ack)
  {
    if (ack.job_id != job_id_ || ack.next_index <= acked_)
      return false;
    acked_ = ack.next_index;
    return true;
  }
  std::uint32_t jobId() const { return job_id_; }
  std::uint64_t acked() const { return acked_; }

private:
  std::uint32_t job_id_ = 0;
  std::uint64_t window_ = 0, sent_ = 0, acked_ = 0;
};
}  // namespace scanhead
