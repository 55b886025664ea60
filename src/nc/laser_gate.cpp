/// \file laser_gate.cpp
/// \brief The laser command on the NC's command timeline with laser-on and laser-off delays
/// (SPEC §2.5).
#include "scanhead/nc/laser_gate.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "scanhead/common/errors.hpp"

namespace scanhead
{
LaserGate::LaserGate(const PathTimeline& timeline, double on_delay_s, double off_delay_s)
  : on_delay_s_(on_delay_s)
{
  if (!std::isfinite(on_delay_s) || !std::isfinite(off_delay_s))
  {
    std::ostringstream msg;
    msg << "laser gate: the laser-on and laser-off delays must be finite (got " << on_delay_s << ", " << off_delay_s
        << ")";
    throw ConfigError(msg.str());
  }
  const std::vector<PathSegment>& segs = timeline.segments();
  std::size_t k = 0;
  while (k < segs.size())
  {
    if (!segs[k].mark)
    {
      ++k;
      continue;
    }
    // A burst: the maximal run of consecutive laser-on segments from k.
    const std::size_t first = k;
    while (k < segs.size() && segs[k].mark)
    {
      ++k;
    }
    LaserWindow w;
    w.burst_start_s = segs[first].t_start_s;
    w.burst_end_s = timeline.segmentEnd(k - 1);
    w.on_s = w.burst_start_s + on_delay_s;
    w.off_s = w.burst_end_s + off_delay_s;
    w.first_segment = first;
    w.end_segment = k;
    if (!(w.on_s < w.off_s))
    {
      continue;  // on delay − off delay >= burst length: the laser never lights
    }
    if (!windows_.empty() && w.on_s < windows_.back().off_s)
    {
      // Overlaps the previous window (off delay > on delay + the gap): one window, the laser stays on.
      LaserWindow& prev = windows_.back();
      prev.burst_end_s = w.burst_end_s;
      prev.off_s = std::max(prev.off_s, w.off_s);
      prev.end_segment = w.end_segment;
    }
    else
    {
      windows_.push_back(w);
      window_piece_begin_.push_back(pieces_.size());
    }
    for (std::size_t j = first; j < k; ++j)
    {
      pieces_.push_back(Piece{segs[j].t_start_s, segs[j].power_w, segs[j].speed_mps});
    }
  }
}

std::size_t LaserGate::lookup(double t_s, Cursor& cursor) const
{
  const std::size_t n_windows = windows_.size();
  std::size_t w = std::min(cursor.window, n_windows);
  while (w > 0 && t_s < windows_[w - 1].off_s)
  {
    --w;  // only for non-monotone readers
  }
  while (w < n_windows && t_s >= windows_[w].off_s)
  {
    ++w;
  }
  cursor.window = w;
  if (w == n_windows || !(t_s >= windows_[w].on_s))
  {
    return npos;
  }
  const LaserWindow& win = windows_[w];
  // The burst's power sequence shifted by the laser-on delay, clamped to the burst: before its
  // start (t − on < burst start, rounding only) the first piece, after its end (the off delay
  // longer than the on delay) the last.
  double tau_s = t_s - on_delay_s_;
  tau_s = tau_s < win.burst_start_s ? win.burst_start_s : (tau_s > win.burst_end_s ? win.burst_end_s : tau_s);
  const std::size_t begin = window_piece_begin_[w];
  const std::size_t last = (w + 1 < n_windows ? window_piece_begin_[w + 1] : pieces_.size()) - 1;
  std::size_t p = std::min(std::max(cursor.piece, begin), last);
  while (p > begin && tau_s < pieces_[p].t_start_s)
  {
    --p;
  }
  while (p < last && tau_s >= pieces_[p + 1].t_start_s)
  {
    ++p;
  }
  cursor.piece = p;
  return p;
}

double LaserGate::powerAt(double t_s, Cursor& cursor) const
{
  const std::size_t p = lookup(t_s, cursor);
  return p == npos ? 0.0 : pieces_[p].power_w;
}

double LaserGate::speedAt(double t_s, Cursor& cursor) const
{
  const std::size_t p = lookup(t_s, cursor);
  return p == npos ? 0.0 : pieces_[p].speed_mps;
}
}  // namespace scanhead
