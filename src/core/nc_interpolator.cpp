/// \file nc_interpolator.cpp
/// \brief The NC stage (SPEC §2): exact timeline → X_inter → IGT → FIR T1 → velocity saturation
/// → FIR T2 → Q_filt2, with the laser gate aligned on the filtered setpoint.
///
/// IGT: Q_inter = OpticalModel::inverse (Newton on the ray trace, to its tolerance), warm-started
/// from the linear extrapolation 2·q_{n−1} − q_{n−2} of the previous solutions (retried from
/// q = 0 if that fails); a sample whose point equals the previous one reuses its solution (the
/// hold after the end).
///
/// Derivatives of Q_filt2 (the setpoint velocity and acceleration):
///  * velocity: exact. Q_filt2(t) is the box mean over T2 of the piecewise-linear signal s(t)
///    through the saturated samples, so dQ_filt2/dt(t_n) = (s_n − s(t_n − T2))/T2 with s
///    linearly interpolated at the fractional delay (BoxFilter::derivative). T2 = 0: the
///    velocity of s below.
///  * velocity of s (after the saturation): where the axis is not limited, the exact derivative
///    of the FIR T1 output, (q_n − q(t_n − T1))/T1 (T1 = 0: backward difference of Q_inter,
///    the left derivative of its linear interpolation); where limited, ±max_joint_speed_radps.
///  * acceleration: the same exact box derivative applied to the velocity samples of s read as
///    a piecewise-linear signal, (ṡ_n − ṡ(t_n − T2))/T2 (T2 = 0: backward difference of ṡ).
///    This is the exact acceleration of box_T2(box_T1(Q_inter)) up to the linear interpolation
///    of the T1 velocity between samples, which differs from the true (kinked) velocity only in
///    the periods containing a kink (O(Ts²·a/T2) on the integrated velocity); it reproduces the
///    rectangle (T1) ⊗ box (T2) trapezoid of SPEC §2.3.
#include "scanhead/core/nc_interpolator.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>

#include "scanhead/core/box_filter.hpp"
#include "scanhead/core/errors.hpp"
#include "scanhead/core/path_timeline.hpp"
#include "scanhead/core/rate_limiter.hpp"

namespace scanhead
{
namespace
{
/// ceil(x) where x within 1e-9 (relative) of an integer counts as that integer.
std::uint64_t ceilSnapped(double x)
{
  const double nearest = std::round(x);
  if (std::abs(x - nearest) <= 1e-9 * std::max(1.0, std::abs(x)))
  {
    return static_cast<std::uint64_t>(std::max(0.0, nearest));
  }
  return static_cast<std::uint64_t>(std::max(0.0, std::ceil(x)));
}

std::string pointText(const Eigen::Vector2d& p)
{
  std::ostringstream s;
  s.precision(9);
  s << "(" << p.x() << ", " << p.y() << ") m";
  return s.str();
}
}  // namespace

struct NcInterpolator::State
{
  PathTimeline timeline;
  PathTimeline::Cursor path_cursor;
  PathTimeline::Cursor laser_cursor;
  BoxFilter<2> fir1;
  RateLimiter limiter;
  BoxFilter<4> fir2;  ///< channels: s (2), ṡ (2)
  Eigen::Vector2d x_prev = Eigen::Vector2d::Zero();  ///< last X_inter [m]
  Eigen::Vector2d q_prev = Eigen::Vector2d::Zero();   ///< Q_inter at the last sample [rad]
  Eigen::Vector2d q_prev2 = Eigen::Vector2d::Zero();  ///< Q_inter one sample before [rad]
  std::uint64_t next = 0;
  std::uint64_t total = 0;
  std::string job_name;
};

NcInterpolator::NcInterpolator(const NcConfig& config, const OpticalModel& optics) : config_(config), optics_(optics)
{
  config_.validate();
}

NcInterpolator::~NcInterpolator() = default;

void NcInterpolator::start(const Job& job)
{
  state_.reset();
  auto st = std::make_unique<State>();
  st->job_name = job.name;
  st->timeline = PathTimeline(job, config_.implicit_jump_speed_mps);
  if (!st->timeline.hasPoints())
  {
    throw InputError("NC: job '" + job.name + "' has no point");
  }

  // Every vertex must be reachable; checked now so a bad job fails at start, not mid-stream.
  // The first point from q = 0 (its Q starts the filters), the others warm-started from the
  // previous vertex, retried from 0.
  Eigen::Vector2d q0 = Eigen::Vector2d::Zero();
  bool first = true;
  Eigen::Vector2d q_guess = Eigen::Vector2d::Zero();
  for (std::size_t p = 0; p < job.polylines.size(); ++p)
  {
    for (std::size_t v = 0; v < job.polylines[p].points.size(); ++v)
    {
      const Eigen::Vector2d& x = job.polylines[p].points[v];
      try
      {
        try
        {
          q_guess = optics_.inverse(x, first ? Eigen::Vector2d::Zero() : q_guess);
        }
        catch (const NumericalError&)
        {
          if (first)
          {
            throw;
          }
          q_guess = optics_.inverse(x, Eigen::Vector2d::Zero());
        }
      }
      catch (const NumericalError& e)
      {
        throw NumericalError("NC: job '" + job.name + "' polyline " + std::to_string(p) + " point " +
                             std::to_string(v) + " " + pointText(x) + " is not reachable by the optics: " + e.what());
      }
      if (first)
      {
        q0 = q_guess;
        first = false;
      }
    }
  }

  const double ts = config_.period_s;
  st->fir1 = BoxFilter<2>(config_.fir_t1_s, ts);
  st->fir1.reset(q0);
  st->limiter = RateLimiter(config_.max_joint_speed_radps, ts);
  st->limiter.reset(q0);
  st->fir2 = BoxFilter<4>(config_.fir_t2_s, ts);
  Eigen::Vector4d s0;
  s0 << q0, 0.0, 0.0;
  st->fir2.reset(s0);
  st->x_prev = st->timeline.startPoint();
  st->q_prev = q0;
  st->q_prev2 = q0;  // at rest before the start
  // Samples n = 0 .. N−1 cover t ∈ [0, path end + T1 + T2 + tail]: the last one is the first
  // sample at or after that time (a time within 1e-9 relative of a sample counts as on it).
  const double end_s = st->timeline.duration() + config_.fir_t1_s + config_.fir_t2_s + config_.tail_s;
  st->total = ceilSnapped(end_s / ts) + 1;
  state_ = std::move(st);
}

NcOutput NcInterpolator::process(std::size_t max_samples)
{
  NcOutput out;
  const double ts = config_.period_s;
  out.setpoint.period_s = ts;
  out.laser.period_s = ts;
  out.debug.period_s = ts;
  if (!state_)
  {
    return out;
  }
  State& st = *state_;
  out.setpoint.first_index = st.next;
  out.laser.first_index = st.next;
  out.debug.first_index = st.next;
  const std::uint64_t remaining = st.total - st.next;
  const std::size_t count = static_cast<std::size_t>(std::min<std::uint64_t>(max_samples, remaining));
  out.setpoint.samples.resize(count);
  out.laser.samples.resize(count);
  if (config_.debug)
  {
    out.debug.samples.resize(count);
  }
  const double delay_s = config_.filterDelay();
  const bool t2_identity = (st.fir2.duration() == 0.0);

  for (std::size_t i = 0; i < count; ++i)
  {
    const std::uint64_t n = st.next + i;
    const double t_s = static_cast<double>(n) * ts;

    // X_inter: the exact point of the timeline at t_n; Q_inter by the IGT, warm-started.
    const Eigen::Vector2d x = st.timeline.positionAt(t_s, st.path_cursor);
    Eigen::Vector2d q = st.q_prev;
    if (x != st.x_prev)
    {
      try
      {
        try
        {
          // Warm start extrapolated from the last two solutions (2·q_{n−1} − q_{n−2}): on a
          // segment its error is O(q̈·Ts²) ~ 1e-10 rad, so Newton needs one step plus the
          // converged check (two ray traces) instead of two steps from q_{n−1}.
          q = optics_.inverse(x, 2.0 * st.q_prev - st.q_prev2);
        }
        catch (const NumericalError&)
        {
          q = optics_.inverse(x, Eigen::Vector2d::Zero());
        }
      }
      catch (const NumericalError& e)
      {
        std::ostringstream msg;
        msg << "NC: job '" << st.job_name << "' sample " << n << " (t = " << t_s << " s): path point "
            << pointText(x) << " is not reachable by the optics: " << e.what();
        state_.reset();  // the job is abandoned: done() is true, start() again to continue
        throw NumericalError(msg.str());
      }
      st.x_prev = x;
    }
    st.q_prev2 = st.q_prev;
    st.q_prev = q;

    // FIR T1, velocity saturation, FIR T2 (per axis, joint space).
    st.fir1.push(q);
    const Eigen::Vector2d q_filt1 = st.fir1.average();
    const Eigen::Vector2d q_filt1_dot = st.fir1.derivative();
    Eigen::Vector2d s;
    Eigen::Vector2d s_dot;
    st.limiter.step(q_filt1, q_filt1_dot, s, s_dot);
    Eigen::Vector4d s_and_rate;
    s_and_rate << s, s_dot;
    st.fir2.push(s_and_rate);
    const Eigen::Vector4d d = st.fir2.derivative();

    SetpointSample& sp = out.setpoint.samples[i];
    if (t2_identity)
    {
      sp.position = s;
      sp.velocity = s_dot;
    }
    else
    {
      sp.position = st.fir2.average().head<2>();
      sp.velocity = d.head<2>();
    }
    sp.acceleration = d.tail<2>();

    // Laser: the power the path commands at t_n − (T1 + T2)/2, i.e. aligned with Q_filt2.
    out.laser.samples[i].power_w = st.timeline.powerAt(t_s - delay_s, st.laser_cursor);

    if (config_.debug)
    {
      NcDebugSample& dbg = out.debug.samples[i];
      dbg.x_inter = x;
      dbg.q_inter = q;
      dbg.q_filt1 = q_filt1;
    }
  }
  st.next += count;
  return out;
}

bool NcInterpolator::done() const
{
  return !state_ || state_->next >= state_->total;
}

std::uint64_t NcInterpolator::totalSamples() const
{
  return state_ ? state_->total : 0;
}

double NcInterpolator::pathDuration() const
{
  return state_ ? state_->timeline.duration() : 0.0;
}
}  // namespace scanhead
