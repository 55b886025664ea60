/// \file adaptive_fir.cpp
/// \brief Speed-adaptive jerk-limiting filter of the work-plane path (SPEC §2.6, NC §3.5).
///
/// Closed forms used (one knot, unit velocity step, centred kernel, u = |τ|, T1 >= T2 >= 0,
/// h = (T1 + T2)/2, a = (T1 − T2)/2). The kernel (acceleration) is the unit-area trapezoid
/// rect_T1 ∗ rect_T2:
/// \f[ k(u) = 1/T_1 \ (u \le a), \qquad k(u) = (h - u)/(T_1 T_2) \ (a \le u \le h), \qquad 0 \ (u \ge h) \f]
/// G(u) = ∫_u^h k (the velocity still missing at τ = u, or reached at τ = −u):
/// \f[ G(u) = \frac{T_2/2 + (a - u)}{T_1} \ (u \le a), \qquad G(u) = \frac{(h-u)^2}{2 T_1 T_2} \ (a \le u \le h) \f]
/// so the velocity response is S(τ) = 1 − G(τ) for τ >= 0 and G(−τ) for τ < 0. The position
/// bracket B(τ) = R(τ) − max(τ, 0) is even (its derivative S − H is odd) and B(u) = ∫_u^h G:
/// \f[ B(u) = \frac{1}{T_1}\Big(\frac{T_2^2}{6} + \frac{T_2 (a-u)}{2} + \frac{(a-u)^2}{2}\Big) \ (u \le a),
///     \qquad B(u) = \frac{(h-u)^3}{6 T_1 T_2} \ (a \le u \le h) \f]
/// (T2 = 0: the box, only the first branch, B = (T1/2 − u)²/(2 T1); T1 = T2: a = 0, only the
/// second). The first stage alone is the box T1: k = 1/T1, G = (T1/2 − u)/T1,
/// B = (T1/2 − u)²/(2 T1) for u <= T1/2.
#include "scanhead/nc/adaptive_fir.hpp"

#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>
#include <sstream>
#include <utility>

#include "scanhead/common/errors.hpp"

namespace scanhead
{
namespace
{
void checkLimits(const PlaneLimits& limits)
{
  if (!(std::isfinite(limits.max_accel_mps2) && limits.max_accel_mps2 > 0.0))
  {
    std::ostringstream msg;
    msg << "adaptive filter: acceleration limit max_accel_mps2 (from nc.max_joint_accel_radps2) must be > 0 (got "
        << limits.max_accel_mps2 << ")";
    throw ConfigError(msg.str());
  }
  if (!(std::isfinite(limits.max_jerk_mps3) && limits.max_jerk_mps3 > 0.0))
  {
    std::ostringstream msg;
    msg << "adaptive filter: jerk limit max_jerk_mps3 (from nc.max_joint_jerk_radps3) must be > 0 (got "
        << limits.max_jerk_mps3 << ")";
    throw ConfigError(msg.str());
  }
}

/// Relative excess over a limit that triggers a lengthening (far above rounding, ~1e-15, far
/// below anything measurable).
constexpr double kLimitSlack = 1e-12;
/// A lengthened kernel gets 2 % more than the excess it took part in: without a margin, close
/// reversals hand the excess from kernel to kernel and converge only after hundreds of passes.
constexpr double kLengthenMargin = 1.02;
}  // namespace

FilterDurations minimalDurations(double step_mps, const PlaneLimits& limits)
{
  checkLimits(limits);
  if (!(std::isfinite(step_mps) && step_mps >= 0.0))
  {
    std::ostringstream msg;
    msg << "adaptive filter: velocity step must be finite and >= 0 (got " << step_mps << ")";
    throw InputError(msg.str());
  }
  FilterDurations d;
  if (step_mps == 0.0)
  {
    return d;
  }
  const double t_accel_s = step_mps / limits.max_accel_mps2;           // Δ/A
  const double t_jerk_s = std::sqrt(step_mps / limits.max_jerk_mps3);  // sqrt(Δ/J)
  if (t_accel_s >= t_jerk_s)
  {
    // Δ >= A²/J: acceleration-limited, T2 = Δ/(J·T1) = A/J (<= T1 up to rounding)
    d.t1_s = t_accel_s;
    d.t2_s = std::min(limits.max_accel_mps2 / limits.max_jerk_mps3, t_accel_s);
  }
  else
  {
    // jerk-limited: the triangle T1 = T2 = sqrt(Δ/J)
    d.t1_s = t_jerk_s;
    d.t2_s = t_jerk_s;
  }
  return d;
}

namespace
{
/// Durations meeting A for a step of accel_step and J for a step of jerk_step (>= accel_step):
/// T1 = max(Δa/A, sqrt(Δj/J)), T2 = Δj/(J·T1) <= T1. Equal steps: minimalDurations.
FilterDurations durationsFor(double accel_step_mps, double jerk_step_mps, const PlaneLimits& limits)
{
  if (accel_step_mps == jerk_step_mps)
  {
    return minimalDurations(accel_step_mps, limits);
  }
  FilterDurations d;
  d.t1_s = std::max(accel_step_mps / limits.max_accel_mps2, std::sqrt(jerk_step_mps / limits.max_jerk_mps3));
  d.t2_s = std::min(jerk_step_mps / (limits.max_jerk_mps3 * d.t1_s), d.t1_s);
  return d;
}
}  // namespace

AdaptiveFir::AdaptiveFir(const PathTimeline& timeline, const PlaneLimits& limits)
  : timeline_(&timeline)
  , limits_(limits)
{
  checkLimits(limits);
  const std::vector<PathSegment>& segs = timeline.segments();
  const std::size_t n_seg = segs.size();
  seg_velocity_.resize(n_seg);
  std::vector<double> speed(n_seg, 0.0);
  double max_speed = 0.0;
  for (std::size_t s = 0; s < n_seg; ++s)
  {
    // a dwell or hold has start = end: velocity exactly 0
    seg_velocity_[s] = (segs[s].end_m - segs[s].start_m) / segs[s].duration_s;
    speed[s] = seg_velocity_[s].norm();
    max_speed = std::max(max_speed, speed[s]);
  }
  longest_ = minimalDurations(2.0 * max_speed, limits);
  const double window_s = longest_.t1_s + longest_.t2_s;  // W

  // Knots: t = 0 (rest → v_0), every boundary where v changes, the end (v_last → rest).
  for (std::size_t s = 0; s <= n_seg; ++s)
  {
    const Eigen::Vector2d before = s > 0 ? seg_velocity_[s - 1] : Eigen::Vector2d::Zero();
    const Eigen::Vector2d after = s < n_seg ? seg_velocity_[s] : Eigen::Vector2d::Zero();
    const Eigen::Vector2d step = after - before;
    if (step.x() == 0.0 && step.y() == 0.0)
    {
      continue;
    }
    Knot knot;
    knot.t_s = s < n_seg ? segs[s].t_start_s : timeline.duration();
    knot.step_mps = step;
    knots_.push_back(knot);
  }

  // V_k: largest speed of the segments overlapping [t_k − W, t_k + W] (sliding-window maximum;
  // both window ends only move forward since the knots are sorted).
  std::deque<std::size_t> best;  // segment indices, speeds decreasing
  std::size_t next = 0;          // next segment to enter the window
  for (Knot& knot : knots_)
  {
    while (next < n_seg && segs[next].t_start_s <= knot.t_s + window_s)
    {
      while (!best.empty() && speed[best.back()] <= speed[next])
      {
        best.pop_back();
      }
      best.push_back(next);
      ++next;
    }
    while (!best.empty() && timeline.segmentEnd(best.front()) < knot.t_s - window_s)
    {
      best.pop_front();
    }
    double v = best.empty() ? 0.0 : speed[best.front()];
    // The segments on either side of a knot overlap its window, so v >= |Δv|/2 already; the
    // guard only matters for a degenerate W.
    v = std::max(v, 0.5 * knot.step_mps.norm());
    knot.local_speed_mps = v;
    knot.durations = minimalDurations(2.0 * v, limits);
  }
  setKernels();

  // Corners closer than T1 + T2 superpose their kernels: the rule above bounds one step at a
  // time, not their sum (two 180° turns one T1 apart reach 2·J; a 90° staircase √2·J).
  // Check the sum exactly and lengthen the kernels that take part in an excess, until none.
  std::vector<double> accel_step(knots_.size());
  std::vector<double> jerk_step(knots_.size());
  for (std::size_t k = 0; k < knots_.size(); ++k)
  {
    accel_step[k] = 2.0 * knots_[k].local_speed_mps;
    jerk_step[k] = accel_step[k];
  }
  std::vector<char> changed(knots_.size(), 1);  // first pass: check everywhere
  constexpr int kMaxPasses = 1000;
  int pass = 0;
  for (; pass < kMaxPasses; ++pass)
  {
    if (!lengthenWhereOverlapsExceed(accel_step, jerk_step, changed))
    {
      break;
    }
    for (std::size_t k = 0; k < knots_.size(); ++k)
    {
      if (changed[k] != 0)
      {
        knots_[k].durations = durationsFor(accel_step[k], jerk_step[k], limits);
      }
    }
    setKernels();
  }
  if (pass == kMaxPasses)
  {
    throw NumericalError("adaptive filter: kernel lengths did not settle within the acceleration and jerk limits");
  }
}

void AdaptiveFir::setKernels()
{
  kernels_.resize(knots_.size());
  delay_s_ = 0.0;
  for (std::size_t k = 0; k < knots_.size(); ++k)
  {
    const Knot& knot = knots_[k];
    Kernel& kern = kernels_[k];
    const double t1 = knot.durations.t1_s;
    const double t2 = knot.durations.t2_s;
    kern.step_mps = knot.step_mps;
    kern.t_s = knot.t_s;
    kern.half_s = 0.5 * (t1 + t2);
    kern.plateau_s = 0.5 * (t1 - t2);
    kern.half_t1_s = 0.5 * t1;
    kern.t2_s = t2;
    kern.inv_t1 = t1 > 0.0 ? 1.0 / t1 : 0.0;
    kern.inv_t1t2 = t2 > 0.0 ? 1.0 / (t1 * t2) : 0.0;
    delay_s_ = std::max(delay_s_, kern.half_s);
  }
  prefix_max_end_s_.resize(kernels_.size());
  suffix_min_start_s_.resize(kernels_.size());
  double run_max = -std::numeric_limits<double>::infinity();
  for (std::size_t k = 0; k < kernels_.size(); ++k)
  {
    run_max = std::max(run_max, kernels_[k].t_s + kernels_[k].half_s);
    prefix_max_end_s_[k] = run_max;
  }
  double run_min = std::numeric_limits<double>::infinity();
  for (std::size_t k = kernels_.size(); k-- > 0;)
  {
    run_min = std::min(run_min, kernels_[k].t_s - kernels_[k].half_s);
    suffix_min_start_s_[k] = run_min;
  }
}

bool AdaptiveFir::lengthenWhereOverlapsExceed(std::vector<double>& accel_step_mps, std::vector<double>& jerk_step_mps,
                                              std::vector<char>& changed) const
{
  // The acceleration Σ Δv_k·k_k(s − t_k) is continuous and piecewise linear in s: its norm peaks
  // at a breakpoint t_k ± a_k, t_k ± h_k. The jerk is piecewise constant: one value per interval
  // between consecutive breakpoints (read at its middle; intervals under 1e-13 s are ignored:
  // the acceleration cannot change there by more than J·1e-13). Only the supports of the
  // kernels flagged in \p changed are checked (the sum is unchanged elsewhere; lengthening only
  // widens a support); on return \p changed flags the kernels lengthened now.
  const std::size_t n = kernels_.size();
  std::vector<std::pair<double, double>> region;  // supports of the flagged kernels, merged
  for (std::size_t k = 0; k < n; ++k)
  {
    if (changed[k] != 0)
    {
      region.emplace_back(kernels_[k].t_s - kernels_[k].half_s, kernels_[k].t_s + kernels_[k].half_s);
    }
  }
  std::sort(region.begin(), region.end());
  std::size_t merged = 0;
  for (std::size_t i = 0; i < region.size(); ++i)
  {
    if (merged > 0 && region[i].first <= region[merged - 1].second)
    {
      region[merged - 1].second = std::max(region[merged - 1].second, region[i].second);
    }
    else
    {
      region[merged++] = region[i];
    }
  }
  region.resize(merged);

  std::vector<double> breaks;
  breaks.reserve(4 * n);
  for (const Kernel& kern : kernels_)
  {
    breaks.push_back(kern.t_s - kern.half_s);
    breaks.push_back(kern.t_s - kern.plateau_s);
    breaks.push_back(kern.t_s + kern.plateau_s);
    breaks.push_back(kern.t_s + kern.half_s);
  }
  std::sort(breaks.begin(), breaks.end());

  const double accel_limit = limits_.max_accel_mps2 * (1.0 + kLimitSlack);
  const double jerk_limit = limits_.max_jerk_mps3 * (1.0 + kLimitSlack);
  std::vector<double> accel_scale(n, 1.0);
  std::vector<double> jerk_scale(n, 1.0);
  bool exceeded = false;
  std::size_t k0 = 0;
  std::size_t r = 0;  // current region
  auto check = [&](double s, bool at_break) {
    while (r < region.size() && region[r].second < s)
    {
      ++r;
    }
    if (r == region.size() || s < region[r].first)
    {
      return;  // nothing changed around s
    }
    while (k0 < n && !(prefix_max_end_s_[k0] > s))
    {
      ++k0;
    }
    Eigen::Vector2d accel = Eigen::Vector2d::Zero();
    Eigen::Vector2d jerk = Eigen::Vector2d::Zero();
    std::size_t k_end = k0;
    for (; k_end < n && suffix_min_start_s_[k_end] < s; ++k_end)
    {
      const Kernel& kern = kernels_[k_end];
      const double tau = s - kern.t_s;
      const double u = std::abs(tau);
      if (!(u < kern.half_s))
      {
        continue;
      }
      if (u > kern.plateau_s)
      {
        accel += ((kern.half_s - u) * kern.inv_t1t2) * kern.step_mps;
        jerk += (tau < 0.0 ? kern.inv_t1t2 : -kern.inv_t1t2) * kern.step_mps;
      }
      else
      {
        accel += kern.inv_t1 * kern.step_mps;
      }
    }
    // at a breakpoint the jerk is one-sided per kernel: only the acceleration is read there
    const double accel_ratio = at_break ? accel.norm() / limits_.max_accel_mps2 : 0.0;
    const double jerk_ratio = at_break ? 0.0 : jerk.norm() / limits_.max_jerk_mps3;
    const bool accel_over = accel_ratio * limits_.max_accel_mps2 > accel_limit;
    const bool jerk_over = jerk_ratio * limits_.max_jerk_mps3 > jerk_limit;
    if (!accel_over && !jerk_over)
    {
      return;
    }
    exceeded = true;
    for (std::size_t k = k0; k < k_end; ++k)
    {
      if (std::abs(s - kernels_[k].t_s) < kernels_[k].half_s)
      {
        // every kernel taking part is lengthened as if its step were that much larger
        if (accel_over)
        {
          accel_scale[k] = std::max(accel_scale[k], accel_ratio * kLengthenMargin);
        }
        if (jerk_over)
        {
          jerk_scale[k] = std::max(jerk_scale[k], jerk_ratio * kLengthenMargin);
        }
      }
    }
  };
  for (std::size_t i = 0; i < breaks.size(); ++i)
  {
    check(breaks[i], true);
    if (i + 1 < breaks.size() && breaks[i + 1] - breaks[i] > 1e-13)
    {
      check(0.5 * (breaks[i] + breaks[i + 1]), false);
    }
  }
  for (std::size_t k = 0; k < n; ++k)
  {
    changed[k] = (accel_scale[k] > 1.0 || jerk_scale[k] > 1.0) ? 1 : 0;
    accel_step_mps[k] *= accel_scale[k];
    jerk_step_mps[k] *= std::max(accel_scale[k], jerk_scale[k]);
  }
  return exceeded;
}

PlaneState AdaptiveFir::filtered(double t_s, Cursor& cursor) const
{
  return evaluate(t_s, cursor, false);
}

PlaneState AdaptiveFir::firstStage(double t_s, Cursor& cursor) const
{
  return evaluate(t_s, cursor, true);
}

PlaneState AdaptiveFir::evaluate(double t_s, Cursor& cursor, bool first_stage) const
{
  PlaneState out;
  if (timeline_ == nullptr)
  {
    return out;
  }
  // X(s) and Ẋ(s) at the path time s = t − D (same rules as PathTimeline::positionAt).
  const double s = t_s - delay_s_;
  const std::size_t seg = timeline_->segmentAt(s, cursor.path);
  if (!(s > 0.0))
  {
    out.position = timeline_->startPoint();
    if (seg != PathTimeline::npos)
    {
      out.velocity = seg_velocity_[seg];  // s = 0 exactly: on the first segment
    }
  }
  else if (seg == PathTimeline::npos)
  {
    out.position = timeline_->endPoint();
  }
  else
  {
    const PathSegment& p = timeline_->segments()[seg];
    double f = (s - p.t_start_s) / p.duration_s;
    f = f < 0.0 ? 0.0 : (f > 1.0 ? 1.0 : f);
    out.position = p.start_m + f * (p.end_m - p.start_m);
    out.velocity = seg_velocity_[seg];
  }

  // Active knots: the kernel of knot k covers s ∈ (t_k − h_k, t_k + h_k). Every knot before
  // first_active has ended (prefix max of the ends < s); scanning stops where every later knot
  // has not started yet (suffix min of the starts >= s).
  const std::size_t n = kernels_.size();
  std::size_t k0 = std::min(cursor.first_active, n);
  while (k0 > 0 && prefix_max_end_s_[k0 - 1] > s)
  {
    --k0;  // only for non-monotone readers
  }
  while (k0 < n && !(prefix_max_end_s_[k0] > s))
  {
    ++k0;
  }
  cursor.first_active = k0;
  for (std::size_t k = k0; k < n && suffix_min_start_s_[k] < s; ++k)
  {
    const Kernel& kern = kernels_[k];
    const double tau = s - kern.t_s;
    const double u = std::abs(tau);
    double b;  // B(u) position bracket [s]
    double g;  // G(u) velocity fraction [-]
    double a;  // k(u) kernel [1/s]
    if (first_stage)
    {
      if (!(u < kern.half_t1_s))
      {
        continue;
      }
      const double r = kern.half_t1_s - u;
      a = kern.inv_t1;
      g = r * kern.inv_t1;
      b = 0.5 * r * r * kern.inv_t1;
    }
    else
    {
      if (!(u < kern.half_s))
      {
        continue;
      }
      if (u >= kern.plateau_s)
      {
        const double r = kern.half_s - u;  // T2 > 0 here since a <= u < h
        a = r * kern.inv_t1t2;
        g = 0.5 * r * a;
        b = (1.0 / 3.0) * r * g;
      }
      else
      {
        const double w = kern.plateau_s - u;
        a = kern.inv_t1;
        g = (0.5 * kern.t2_s + w) * kern.inv_t1;
        b = (kern.t2_s * kern.t2_s * (1.0 / 6.0) + 0.5 * kern.t2_s * w + 0.5 * w * w) * kern.inv_t1;
      }
    }
    out.position += b * kern.step_mps;
    out.velocity += (tau >= 0.0 ? -g : g) * kern.step_mps;
    out.acceleration += a * kern.step_mps;
  }
  return out;
}
}  // namespace scanhead
