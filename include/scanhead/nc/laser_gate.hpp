/// \file laser_gate.hpp
/// \brief The laser command on the NC's command timeline, with laser-on and laser-off delays
/// (SPEC §2.5).
#pragma once

#include <cstddef>
#include <vector>

#include "scanhead/job/path_timeline.hpp"

namespace scanhead
{
/// \brief One run of the laser: a burst of consecutive laser-on segments (moves, dwells and
/// polygon holds with mark = true) on [burst_start_s, burst_end_s), lit on [on_s, off_s).
struct LaserWindow
{
  double burst_start_s = 0.0;     ///< the NC starts marking [s]
  double burst_end_s = 0.0;       ///< the NC stops marking [s]
  double on_s = 0.0;              ///< burst_start + laser-on delay [s]
  double off_s = 0.0;             ///< burst_end + laser-off delay [s]
  std::size_t first_segment = 0;  ///< first segment of the burst
  std::size_t end_segment = 0;    ///< one past its last segment
};

class LaserGate
{
public:
  /// \brief Where to resume; one per monotone reader.
  struct Cursor
  {
    std::size_t window = 0;
    std::size_t piece = 0;
  };

  LaserGate() = default;
  /// \param[in] timeline read now; the gate keeps its own copy of the bursts' powers and speeds
  /// \param[in] on_delay_s  any finite value (negative: before the NC starts the mark) [s]
  /// \param[in] off_delay_s any finite value [s]
  /// Windows that come out empty (on >= off) light nothing and are left out of windows();
  /// windows that overlap (the next on_s < this off_s) merge into one: burst_start, on_s and
  /// first_segment of the first, burst_end, off_s and end_segment of the last. Inside a merged
  /// window, a shifted time falling in the laser-off gap between its bursts reads the last
  /// laser-on segment before the gap (the power command is held). \throws ConfigError if a delay
  /// is not finite
  LaserGate(const PathTimeline& timeline, double on_delay_s, double off_delay_s);

  /// \brief Laser power at command time \p t_s [W]: 0 outside every window; inside window w,
  /// the power of the burst's segment at clamp(t − on_delay, burst_start, burst_end) (the burst's
  /// power sequence shifted by the laser-on delay).
  double powerAt(double t_s, Cursor& cursor) const;

  /// \brief Programmed speed of the segment powerAt reads at \p t_s [m/s], 0 outside windows.
  double speedAt(double t_s, Cursor& cursor) const;

  const std::vector<LaserWindow>& windows() const { return windows_; }

private:
  /// One laser-on segment of a window's bursts (gap segments of merged windows are left out, so
  /// a time in a gap reads the last piece before it: the power is held).
  struct Piece
  {
    double t_start_s = 0.0;  ///< segment start on the command timeline [s]
    double power_w = 0.0;    ///< [W]
    double speed_mps = 0.0;  ///< programmed speed [m/s]
  };

  /// Index into pieces_ of the piece powerAt reads at \p t_s, or npos outside every window.
  std::size_t lookup(double t_s, Cursor& cursor) const;

  static constexpr std::size_t npos = static_cast<std::size_t>(-1);

  double on_delay_s_ = 0.0;
  std::vector<LaserWindow> windows_;
  std::vector<std::size_t> window_piece_begin_;  ///< first piece of each window (ends: next begin)
  std::vector<Piece> pieces_;
};
}  // namespace scanhead
