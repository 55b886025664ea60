/// \file km0_protocol.cpp
/// \brief KM0 signal (THESIS Fig. 2.57) through the NC's joint filters, run through an axis, and
/// the step / ramp metrics of THESIS Fig. 2.58–2.59.
#include "scanhead/servo/km0/km0_protocol.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "scanhead/common/box_filter.hpp"
#include "scanhead/common/errors.hpp"
#include "scanhead/common/number_text.hpp"
#include "scanhead/servo/galvo_servo.hpp"

namespace scanhead
{
namespace
{
constexpr double kPi = 3.14159265358979323846;
constexpr double kRadPerDeg = kPi / 180.0;
const double kNaN = std::numeric_limits<double>::quiet_NaN();

/// One command of the signal: the target jumps to \p to and the saturation is \p speed.
struct Command
{
  Km0PhaseKind kind;
  double to_rad;
  double speed_radps;
  double hold_s;    ///< phase duration [s]
  double steady_s;  ///< length of the steady window at the phase's end [s]
};

std::size_t samplesFor(double duration_s, double period_s)
{
  return static_cast<std::size_t>(std::ceil(duration_s / period_s - 1e-9));
}

/// Mean of x over [a, b).
double mean(const std::vector<double>& x, std::size_t a, std::size_t b)
{
  double sum = 0.0;
  for (std::size_t k = a; k < b; ++k)
    sum += x[k];
  return sum / static_cast<double>(b - a);
}

/// dθ/dt at k by central differences (one-sided at the array ends) [rad/s].
double centralSpeed(const std::vector<double>& x, std::size_t k, double period_s)
{
  if (k == 0)
    return (x[1] - x[0]) / period_s;
  if (k + 1 >= x.size())
    return (x[k] - x[k - 1]) / period_s;
  return (x[k + 1] - x[k - 1]) / (2.0 * period_s);
}

/// Time (in samples after \p k) where a signal whose excess over the band is e_k > 0 at k and
/// e_{k+1} ≤ 0 at k + 1 crosses it, by linear interpolation.
double crossingFraction(double excess_k, double excess_next)
{
  const double denom = excess_k - excess_next;
  return denom > 0.0 ? excess_k / denom : 0.0;
}

void checkPhase(std::size_t size, const Km0Phase& phase, const char* what)
{
  if (phase.end > size || phase.begin + 4 > phase.end)
  {
    std::ostringstream msg;
    msg << what << ": phase [" << phase.begin << ", " << phase.end << ") does not fit " << size
        << " samples or is shorter than 4";
    throw InputError(msg.str());
  }
}
}  // namespace

const char* km0PhaseName(Km0PhaseKind kind)
{
  switch (kind)
  {
    case Km0PhaseKind::Positioning:
      return "positioning";
    case Km0PhaseKind::SmallStep:
      return "small_step";
    case Km0PhaseKind::LargeStep:
      return "large_step";
    case Km0PhaseKind::Ramp:
      return "ramp";
  }
  return "unknown";
}

Km0Signal makeKm0Signal(const Km0SignalConfig& config, double period_s)
{
  config.validate();
  if (!(period_s > 0.0) || !std::isfinite(period_s))
    throw ConfigError("km0 period_s must be > 0 (got " + sixDigitText(period_s) + ")");
  const double centre = 0.5 * (config.joint_lower_rad + config.joint_upper_rad);
  const double half = 0.5 * (config.joint_upper_rad - config.joint_lower_rad) - config.range_margin_deg * kRadPerDeg;
  if (!(half > 0.0))
    throw ConfigError("km0.signal.range_margin_deg leaves no usable range (got " +
                      sixDigitText(config.range_margin_deg) + ")");
  const double filters_s = config.fir_t1_s + config.fir_t2_s;
  const double vmax = config.max_speed_radps;

  std::vector<Command> commands;
  double current = centre;
  auto stepTo = [&](Km0PhaseKind kind, double to) {
    const double travel_s = std::abs(to - current) / vmax + filters_s;
    commands.push_back({kind, to, vmax, travel_s + config.step_hold_s, 0.5 * config.step_hold_s});
    current = to;
  };
  for (double a_deg : config.small_steps_deg)
  {
    const double a = a_deg * kRadPerDeg;
    if (std::abs(a) > half)
      throw ConfigError("km0.signal.small_steps_deg: " + sixDigitText(a_deg) + " leaves the joint range");
    stepTo(Km0PhaseKind::SmallStep, centre + a);
    stepTo(Km0PhaseKind::SmallStep, centre);
  }
  for (double a_deg : config.large_steps_deg)
  {
    const double a = a_deg * kRadPerDeg;
    if (0.5 * std::abs(a) > half)
      throw ConfigError("km0.signal.large_steps_deg: " + sixDigitText(a_deg) + " leaves the joint range");
    stepTo(Km0PhaseKind::Positioning, centre - 0.5 * a);
    stepTo(Km0PhaseKind::LargeStep, centre + 0.5 * a);
    stepTo(Km0PhaseKind::LargeStep, centre - 0.5 * a);
  }
  for (double v : config.ramp_speeds_radps)
  {
    if (v > vmax)
      throw ConfigError("km0.signal.ramp_speeds_radps: " + sixDigitText(v) + " exceeds max_speed_radps " +
                        sixDigitText(vmax));
    const double amplitude = std::min(2.0 * half, v * config.ramp_duration_s);
    if (amplitude / v < config.min_ramp_duration_s)
    {
      throw ConfigError("km0.signal.ramp_speeds_radps: at " + sixDigitText(v) + " rad/s the range allows a ramp of " +
                        sixDigitText(amplitude / v) + " s < min_ramp_duration_s");
    }
    stepTo(Km0PhaseKind::Positioning, centre - 0.5 * amplitude);
    for (double to : {centre + 0.5 * amplitude, centre - 0.5 * amplitude})
    {
      commands.push_back({Km0PhaseKind::Ramp, to, v, amplitude / v + filters_s + config.ramp_hold_s, 0.0});
    }
    current = centre - 0.5 * amplitude;
  }
  stepTo(Km0PhaseKind::Positioning, centre);

  // Phases and the target, sample by sample.
  Km0Signal signal;
  signal.period_s = period_s;
  const std::size_t start = std::max<std::size_t>(1, samplesFor(config.start_hold_s, period_s));
  std::size_t total = start;
  for (const Command& c : commands)
    total += samplesFor(c.hold_s, period_s);
  total += 1;
  signal.target_rad.assign(total, centre);
  std::vector<double> speed(total, vmax);
  std::size_t n0 = start;  // first sample at the new target
  double from = centre;
  for (const Command& c : commands)
  {
    const std::size_t len = samplesFor(c.hold_s, period_s);
    Km0Phase phase;
    phase.kind = c.kind;
    phase.begin = n0 - 1;
    phase.end = n0 - 1 + len;
    phase.steady_begin = phase.end - std::min(len - 1, std::max<std::size_t>(1, samplesFor(c.steady_s, period_s)));
    phase.from_rad = from;
    phase.to_rad = c.to_rad;
    phase.speed_radps = c.speed_radps;
    signal.phases.push_back(phase);
    for (std::size_t n = n0; n < n0 + len; ++n)
    {
      signal.target_rad[n] = c.to_rad;
      speed[n] = c.speed_radps;
    }
    from = c.to_rad;
    n0 += len;
  }
  for (std::size_t n = n0; n < total; ++n)
    signal.target_rad[n] = from;

  // NC joint pipeline (SPEC §2, nc_interpolator.cpp): box T1 → velocity saturation → box T2.
  BoxFilter<1> fir1(config.fir_t1_s, period_s);
  BoxFilter<2> fir2(config.fir_t2_s, period_s);  // channels: s, ṡ
  const bool t2_identity = !(config.fir_t2_s > 0.0);
  fir1.reset(Eigen::Matrix<double, 1, 1>::Constant(centre));
  fir2.reset(Eigen::Vector2d(centre, 0.0));
  signal.position_rad.resize(total);
  signal.velocity_radps.resize(total);
  signal.acceleration_radps2.resize(total);
  signal.limited.assign(total, 0);
  double s = centre;
  for (std::size_t n = 0; n < total; ++n)
  {
    fir1.push(Eigen::Matrix<double, 1, 1>::Constant(signal.target_rad[n]));
    const double q1 = fir1.average()(0);
    const double q1_dot = fir1.derivative()(0);
    const double max_step = speed[n] * period_s;
    const double dz = q1 - s;
    double s_dot;
    if (dz > max_step)
    {
      s += max_step;
      s_dot = speed[n];
      signal.limited[n] = 1;
    }
    else if (dz < -max_step)
    {
      s -= max_step;
      s_dot = -speed[n];
      signal.limited[n] = 1;
    }
    else
    {
      s = q1;
      s_dot = std::clamp(q1_dot, -speed[n], speed[n]);
    }
    fir2.push(Eigen::Vector2d(s, s_dot));
    const Eigen::Vector2d d = fir2.derivative();
    if (t2_identity)
    {
      signal.position_rad[n] = s;
      signal.velocity_radps[n] = s_dot;
    }
    else
    {
      signal.position_rad[n] = fir2.average()(0);
      signal.velocity_radps[n] = d(0);
    }
    signal.acceleration_radps2[n] = d(1);
  }
  return signal;
}

Km0Response runKm0(AxisModel& axis, const Km0Signal& signal)
{
  const std::size_t n = signal.position_rad.size();
  Km0Response r;
  r.position_rad.resize(n);
  r.velocity_radps.resize(n);
  r.current_a.resize(n);
  if (n == 0)
    return r;
  axis.reset(signal.position_rad[0]);
  for (std::size_t k = 0; k < n; ++k)
  {
    const AxisModel::Output out =
        axis.step(signal.position_rad[k], signal.velocity_radps[k], signal.acceleration_radps2[k]);
    r.position_rad[k] = out.position;
    r.velocity_radps[k] = out.velocity;
    r.current_a[k] = out.current;
  }
  return r;
}

Km0StepMetrics measureStep(const std::vector<double>& x, const Km0Phase& phase, double period_s,
                           double start_threshold_rad, double band)
{
  checkPhase(x.size(), phase, "measureStep");
  Km0StepMetrics m;
  m.kind = phase.kind;
  m.begin_time_s = static_cast<double>(phase.begin) * period_s;
  m.command_from_rad = phase.from_rad;
  m.command_to_rad = phase.to_rad;
  const std::size_t b = phase.begin;
  const std::size_t e = phase.end;
  const std::size_t sb = (phase.steady_begin > b && phase.steady_begin < e) ? phase.steady_begin : b + (e - b) / 2;
  const double x0 = x[b];
  m.initial_rad = x0;
  m.steady_rad = mean(x, sb, e);
  m.static_error_rad = phase.to_rad - m.steady_rad;

  // (4) start delay: first crossing of |θ − θ0| = threshold.
  m.start_delay_s = kNaN;
  for (std::size_t k = b + 1; k < e; ++k)
  {
    const double dk = std::abs(x[k] - x0);
    if (dk > start_threshold_rad)
    {
      const double dp = std::abs(x[k - 1] - x0);
      const double frac = (start_threshold_rad - dp) / (dk - dp);
      m.start_delay_s = (static_cast<double>(k - 1 - b) + frac) * period_s;
      break;
    }
  }

  const double amplitude = m.steady_rad - x0;
  const double sign = amplitude >= 0.0 ? 1.0 : -1.0;
  const double abs_amplitude = std::abs(amplitude);
  double peak = 0.0;
  double peak_speed = 0.0;
  for (std::size_t k = b; k < e; ++k)
  {
    peak = std::max(peak, sign * (x[k] - m.steady_rad));
    peak_speed = std::max(peak_speed, std::abs(centralSpeed(x, k, period_s)));
  }
  m.peak_speed_radps = peak_speed;
  m.overshoot_pct = abs_amplitude > 0.0 ? 100.0 * peak / abs_amplitude : kNaN;

  // (7) settling: last sample outside steady ± band·|A|, interpolated to the band edge.
  const double half_band = band * abs_amplitude;
  m.settling_time_s = kNaN;
  for (std::size_t k = e; k-- > b;)
  {
    const double excess = std::abs(x[k] - m.steady_rad) - half_band;
    if (excess > 0.0)
    {
      if (k + 1 < e)
      {
        const double next = std::abs(x[k + 1] - m.steady_rad) - half_band;
        m.settling_time_s = (static_cast<double>(k - b) + crossingFraction(excess, next)) * period_s;
      }
      break;
    }
    if (k == b)
      m.settling_time_s = 0.0;
  }
  return m;
}

std::size_t rampEndIndex(const Km0Signal& signal, const Km0Phase& phase)
{
  const double v = phase.speed_radps * (phase.to_rad >= phase.from_rad ? 1.0 : -1.0);
  for (std::size_t k = std::min(phase.end, signal.velocity_radps.size()); k-- > phase.begin;)
  {
    if (std::abs(signal.velocity_radps[k] - v) <= 1e-9 * std::abs(v))
      return k;
  }
  throw InputError("rampEndIndex: the ramp phase at sample " + std::to_string(phase.begin) +
                   " never reaches its speed " + sixDigitText(v) + " rad/s");
}

Km0RampMetrics measureRamp(const std::vector<double>& sp, const std::vector<double>& x,
                           const std::vector<double>& current, const Km0Phase& phase, std::size_t ramp_end,
                           double period_s, double band, double kc_nm_per_a)
{
  checkPhase(std::min({sp.size(), x.size(), current.size()}), phase, "measureRamp");
  if (!(ramp_end > phase.begin + 2 && ramp_end + 1 < phase.end))
    throw InputError("measureRamp: ramp end " + std::to_string(ramp_end) + " outside its phase");
  Km0RampMetrics m;
  const double sign = phase.to_rad >= phase.from_rad ? 1.0 : -1.0;
  m.begin_time_s = static_cast<double>(phase.begin) * period_s;
  m.command_speed_radps = sign * phase.speed_radps;
  m.command_from_rad = phase.from_rad;
  m.command_to_rad = phase.to_rad;
  const std::size_t b = phase.begin;
  const std::size_t e = ramp_end;
  const std::size_t mid = b + (e - b) / 2;
  m.ramp_end_time_s = static_cast<double>(e - b) * period_s;
  m.steady_speed_radps = (x[e] - x[mid]) / (static_cast<double>(e - mid) * period_s);
  m.following_error_rad = sign * (sp[e] - x[e]);
  m.steady_current_a = mean(current, mid, e + 1);
  m.friction_torque_nm = kc_nm_per_a * m.steady_current_a;

  const double half_band = band * std::abs(m.steady_speed_radps);
  m.speed_settling_time_s = kNaN;
  for (std::size_t k = e + 1; k-- > b;)
  {
    const double excess = std::abs(centralSpeed(x, k, period_s) - m.steady_speed_radps) - half_band;
    if (excess > 0.0)
    {
      if (k < e)
      {
        const double next = std::abs(centralSpeed(x, k + 1, period_s) - m.steady_speed_radps) - half_band;
        m.speed_settling_time_s = (static_cast<double>(k - b) + crossingFraction(excess, next)) * period_s;
      }
      break;
    }
    if (k == b)
      m.speed_settling_time_s = 0.0;
  }
  return m;
}

Km0FrictionFit fitFriction(const std::vector<Km0RampMetrics>& ramps)
{
  Km0FrictionFit fit;
  int positive = 0, negative = 0;
  for (const Km0RampMetrics& r : ramps)
    (r.steady_speed_radps > 0.0 ? positive : negative) += 1;
  if (positive < 2 || negative < 2)
    return fit;
  // Columns scaled to comparable size (ω by its largest value) for a well-conditioned QR solve.
  double w_scale = 0.0;
  for (const Km0RampMetrics& r : ramps)
    w_scale = std::max(w_scale, std::abs(r.steady_speed_radps));
  const Eigen::Index n = static_cast<Eigen::Index>(ramps.size());
  Eigen::MatrixXd a(n, 3);
  Eigen::VectorXd y(n);
  for (Eigen::Index i = 0; i < n; ++i)
  {
    const double w = ramps[static_cast<std::size_t>(i)].steady_speed_radps;
    a(i, 0) = w / w_scale;
    a(i, 1) = 1.0;
    a(i, 2) = w > 0.0 ? 1.0 : -1.0;
    y(i) = ramps[static_cast<std::size_t>(i)].friction_torque_nm;
  }
  const Eigen::Vector3d p = a.colPivHouseholderQr().solve(y);
  fit.viscous_nms = p(0) / w_scale;
  fit.offset_torque_nm = p(1);
  fit.coulomb_torque_nm = p(2);
  fit.rms_residual_nm = std::sqrt((a * p - y).squaredNorm() / static_cast<double>(n));
  fit.valid = true;
  return fit;
}

Km0Results measureKm0(const Km0Signal& signal, const Km0Response& response, const Km0MetricConfig& metric,
                      double kc_nm_per_a)
{
  metric.validate();
  Km0Results results;
  const double threshold_rad = metric.start_threshold_deg * kRadPerDeg;
  for (const Km0Phase& phase : signal.phases)
  {
    if (phase.kind == Km0PhaseKind::SmallStep || phase.kind == Km0PhaseKind::LargeStep)
    {
      Km0StepMetrics m =
          measureStep(response.position_rad, phase, signal.period_s, threshold_rad, metric.settling_band);
      m.setpoint_limited = std::any_of(signal.limited.begin() + static_cast<std::ptrdiff_t>(phase.begin),
                                       signal.limited.begin() + static_cast<std::ptrdiff_t>(phase.end),
                                       [](unsigned char c) { return c != 0; });
      results.steps.push_back(m);
    }
    else if (phase.kind == Km0PhaseKind::Ramp)
    {
      results.ramps.push_back(measureRamp(signal.position_rad, response.position_rad, response.current_a, phase,
                                          rampEndIndex(signal, phase), signal.period_s, metric.settling_band,
                                          kc_nm_per_a));
    }
  }
  results.friction_fit = fitFriction(results.ramps);
  return results;
}
}  // namespace scanhead
