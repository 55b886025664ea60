/// \file laser_settling.hpp
/// \brief Laser-on samples while the mirrors have not yet reached a mark, or have already left
/// it: what a too short laser-on delay or a too long laser-off delay burns (SPEC §2.5, THESIS §2.6).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "scanhead/common/chunk.hpp"
#include "scanhead/nc/nc_program.hpp"

namespace scanhead
{
struct LaserSettlingCounts
{
  std::uint64_t early_samples = 0;  ///< laser on before the spot first came within tolerance of its mark
  std::uint64_t late_samples = 0;   ///< laser on after the NC left the mark, spot beyond tolerance of its last segment
  double early_energy_j = 0.0;      ///< Σ P·Ts over the early samples [J]
  double late_energy_j = 0.0;       ///< Σ P·Ts over the late samples [J]
  double worst_distance_m = 0.0;    ///< largest distance of an early or late sample to its segment [m]
};

/// \brief Attributes every laser-on sample to its laser window (laser_gate.hpp) by time:
/// sample n (t_n = n·Ts) is in window w if t_n − gate_shift ∈ [on_w, off_w). Within window w:
///  - early: until the actual spot first comes within \p tolerance_m of the burst's path so far
///    (its segments from the first to the one the filtered path is on, t_n − filter_delay; a hold
///    or a dwell: its point), every laser-on sample farther than that counts;
///  - late: once the filtered path has left the burst (t_n − filter_delay >= burst end), laser-on
///    samples farther than the tolerance from the burst's last segment count.
/// Chunk sizes do not change the counts; memory is the window list.
class LaserSettlingCheck
{
public:
  /// \param[in] program      the NC program the stream was made from (copied: windows and end segments)
  /// \param[in] gate_shift_s NcStats: filter_delay_s − (T1 + T2)/2 (0 with fixed filters) [s]
  /// \param[in] filter_delay_s delay of Q_filt2 behind the command [s]
  /// \param[in] tolerance_m  > 0 [m]
  LaserSettlingCheck(const NcProgram& program, double gate_shift_s, double filter_delay_s, double tolerance_m);

  void process(const SpotChunk& chunk);
  const LaserSettlingCounts& counts() const { return counts_; }

private:
  struct Segment
  {
    Eigen::Vector2d a, b;  ///< ends [m]
    double t_start_s;      ///< on the command timeline [s]
  };
  struct Window
  {
    double on_s, off_s, burst_end_s;
    std::size_t first, end;  ///< the burst's segments in segments_
  };
  std::vector<Segment> segments_;  ///< the bursts' segments, in order
  std::vector<Window> windows_;
  double gate_shift_s_;
  double filter_delay_s_;
  double tolerance_m_;
  std::size_t current_ = 0;                                    ///< first window not yet ended
  std::size_t arrived_window_ = static_cast<std::size_t>(-1);  ///< window whose spot has reached the mark
  LaserSettlingCounts counts_;
};
}  // namespace scanhead
