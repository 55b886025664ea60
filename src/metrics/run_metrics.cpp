/// \file run_metrics.cpp
/// \brief Corner figures (NC §3.2–3.3, SPEC §2 and §5) and stream counters.
#include "scanhead/metrics/run_metrics.hpp"
#include "scanhead/common/segment_distance.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <utility>

namespace scanhead
{
namespace
{
constexpr double kInf = std::numeric_limits<double>::infinity();

/// \brief +inf (never touched) becomes NaN ("no data").
double orNan(double v)
{
  return std::isinf(v) ? std::numeric_limits<double>::quiet_NaN() : v;
}
}  // namespace

CornerPathStats theoreticalCorner(double speed_mps, double angle_rad, double t1_s, double t2_s)
{
  if (t1_s < t2_s)
  {
    std::swap(t1_s, t2_s);  // box filters commute: only the longer/shorter roles matter
  }
  CornerPathStats s;
  s.min_speed_mps = speed_mps * std::abs(std::cos(0.5 * angle_rad));
  s.max_contour_error_m =
      t1_s > 0.0 ? speed_mps * (t2_s * t2_s + 3.0 * t1_s * t1_s) / (12.0 * t1_s) * std::abs(std::sin(0.5 * angle_rad))
                 : 0.0;
  return s;
}

// ---------------------------------------------------------------------------------------------
// CornerTracker

CornerTracker::CornerTracker(std::vector<Corner> corners, double setpoint_delay_s, double actual_delay_s)
  : corners_(std::move(corners))
{
  const std::size_t n = corners_.size();
  order_.resize(n);
  std::iota(order_.begin(), order_.end(), std::size_t(0));
  std::stable_sort(order_.begin(), order_.end(),
                   [this](std::size_t a, std::size_t b) { return corners_[a].time_s < corners_[b].time_s; });
  start_s_.resize(n);
  end_s_.resize(n);
  max_end_s_.resize(n);
  min_start_s_.resize(n);
  for (std::size_t i = 0; i < n; ++i)
  {
    const Corner& c = corners_[order_[i]];
    start_s_[i] = c.time_s - c.window_in_s;
    end_s_[i] = c.time_s + c.window_out_s;
    max_end_s_[i] = i == 0 ? end_s_[i] : std::max(max_end_s_[i - 1], end_s_[i]);
  }
  for (std::size_t i = n; i-- > 0;)
  {
    min_start_s_[i] = i + 1 == n ? start_s_[i] : std::min(min_start_s_[i + 1], start_s_[i]);
  }
  CornerPathStats untouched;
  untouched.min_speed_mps = kInf;
  untouched.max_contour_error_m = kInf;
  setpoint_.delay_s = setpoint_delay_s;
  setpoint_.position = &SpotSample::setpoint;
  setpoint_.stats.assign(n, untouched);
  actual_.delay_s = actual_delay_s;
  actual_.position = &SpotSample::actual;
  actual_.stats.assign(n, untouched);
}

void CornerTracker::process(const SpotChunk& chunk)
{
  period_s_ = chunk.period_s;
  const std::size_t n = chunk.samples.size();
  const bool started = sequence_.started();
  const ChunkAdmission admission = sequence_.admit(chunk.first_index, n);
  if (admission.broken(started))
  {
    history_ = 0;  // gap: do not join the path across it
  }
  for (std::size_t k = admission.skip; k < n; ++k)  // earlier ones already seen
  {
    const std::uint64_t index = chunk.first_index + k;
    const SpotSample& s = chunk.samples[k];
    if (history_ >= 1 && !corners_.empty())
    {
      advance(setpoint_, index, s);
      advance(actual_, index, s);
    }
    prev_[0] = prev_[1];
    prev_[1] = s;
    history_ = std::min(history_ + 1, 2);
  }
}

void CornerTracker::advance(Track& track, std::uint64_t index, const SpotSample& sample)
{
  // New sample `index` (b); prev_[1] is index − 1 (a), prev_[0] is index − 2 if history_ == 2.
  const double t_a = static_cast<double>(index - 1) * period_s_ - track.delay_s;
  const double t_b = static_cast<double>(index) * period_s_ - track.delay_s;
  const std::size_t n = start_s_.size();
  while (track.lo < n && max_end_s_[track.lo] < t_a)
  {
    ++track.lo;  // every corner up to lo has closed before t_a (prefix max), for good
  }
  const Eigen::Vector2d& a = prev_[1].*track.position;
  const Eigen::Vector2d& b = sample.*track.position;
  const bool has_speed = history_ >= 2;
  const double speed = has_speed ? (b - prev_[0].*track.position).norm() / (2.0 * period_s_) : 0.0;
  for (std::size_t c = track.lo; c < n && min_start_s_[c] <= t_b; ++c)
  {
    if (start_s_[c] > t_b || end_s_[c] < t_a)
    {
      continue;  // this corner's window misses [t_a, t_b] (suffix min lets later ones qualify)
    }
    CornerPathStats& st = track.stats[c];
    const double d = pointSegmentDistance(corners_[order_[c]].point, a, b);
    st.max_contour_error_m = std::min(st.max_contour_error_m, d);
    if (has_speed && start_s_[c] <= t_a)  // sample a (central difference b − prev_[0]) in the window
    {
      st.min_speed_mps = std::min(st.min_speed_mps, speed);
    }
  }
}

std::vector<CornerReport> CornerTracker::reports(double t1_s, double t2_s) const
{
  std::vector<CornerReport> out(corners_.size());
  for (std::size_t i = 0; i < order_.size(); ++i)
  {
    const std::size_t original = order_[i];
    CornerReport& r = out[original];
    r.corner = corners_[original];
    r.setpoint.min_speed_mps = orNan(setpoint_.stats[i].min_speed_mps);
    r.setpoint.max_contour_error_m = orNan(setpoint_.stats[i].max_contour_error_m);
    r.actual.min_speed_mps = orNan(actual_.stats[i].min_speed_mps);
    r.actual.max_contour_error_m = orNan(actual_.stats[i].max_contour_error_m);
    r.theory = theoreticalCorner(r.corner.speed_mps, r.corner.angle_rad, t1_s, t2_s);
  }
  return out;
}

// ---------------------------------------------------------------------------------------------
// StreamCounter

void StreamCounter::reset()
{
  *this = StreamCounter();
}

void StreamCounter::process(const SpotChunk& chunk)
{
  period_s_ = chunk.period_s;
  const std::uint64_t n = chunk.samples.size();
  if (n == 0)
  {
    return;
  }
  const std::size_t skip = sequence_.admit(chunk.first_index, n).skip;  // counts gaps and overlaps
  for (std::size_t k = skip; k < n; ++k)
  {
    const double power = chunk.samples[k].power_w;
    if (power > 0.0)
    {
      laser_on_s_ += chunk.period_s;
    }
    energy_j_ += power * chunk.period_s;
  }
}
}  // namespace scanhead
