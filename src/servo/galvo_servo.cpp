/// \file galvo_servo.cpp
#include "scanhead/servo/galvo_servo.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <sstream>

#include "scanhead/common/errors.hpp"
#include "scanhead/servo/cascade_axis.hpp"
#include "scanhead/servo/foh_discretisation.hpp"
#include "scanhead/servo/hinf/hinf_synthesis.hpp"

namespace scanhead
{
namespace
{
constexpr double kPi = 3.14159265358979323846;

/// \brief Both axes sample-major with direct (devirtualised) calls of the final classes.
template <class Axis>
void stepBoth(Axis& ax, Axis& ay, const SetpointChunk& setpoint, JointChunk& out)
{
  const std::size_t n = setpoint.samples.size();
  for (std::size_t k = 0; k < n; ++k)
  {
    const SetpointSample& s = setpoint.samples[k];
    const AxisModel::Output ox = ax.step(s.position[0], s.velocity[0], s.acceleration[0]);
    const AxisModel::Output oy = ay.step(s.position[1], s.velocity[1], s.acceleration[1]);
    JointSample& j = out.samples[k];
    j.position = Eigen::Vector2d(ox.position, oy.position);
    j.velocity = Eigen::Vector2d(ox.velocity, oy.velocity);
    j.current = Eigen::Vector2d(ox.current, oy.current);
  }
}

/// \brief |H0(jΩ)|² of the normalised loop (SPEC §3 first fidelity; see naturalFrequencyForBandwidth).
double normalisedGainSquared(double omega, double zeta, double ratio)
{
  const double re = 1.0 - omega * omega;
  const double im = 2.0 * zeta * omega;
  return ratio * ratio / ((re * re + im * im) * (omega * omega + ratio * ratio));
}
}  // namespace

double naturalFrequencyForBandwidth(const AxisLoopConfig& config)
{
  const double zeta = config.damping;
  const double ratio = config.pole_ratio;
  // Geometric scan from far below every corner (Ω ≤ 1e-3·min(1, r)) to bracket the first crossing
  // of |H0|² = 1/2, then bisection to the last bit.
  double lo = 1e-3 * std::min(1.0, ratio);
  double hi = lo;
  bool found = false;
  for (int i = 0; i < 20000 && hi < 1e9; ++i)
  {
    hi = lo * 1.01;
    if (normalisedGainSquared(hi, zeta, ratio) < 0.5)
    {
      found = true;
      break;
    }
    lo = hi;
  }
  if (!found || normalisedGainSquared(lo, zeta, ratio) < 0.5)
  {
    std::ostringstream msg;
    msg << "naturalFrequencyForBandwidth: no -3 dB crossing for damping " << zeta << ", pole_ratio " << ratio;
    throw NumericalError(msg.str());
  }
  for (int i = 0; i < 200; ++i)
  {
    const double mid = 0.5 * (lo + hi);
    if (mid <= lo || mid >= hi)
    {
      break;
    }
    (normalisedGainSquared(mid, zeta, ratio) < 0.5 ? hi : lo) = mid;
  }
  const double omega3db = 0.5 * (lo + hi);
  return 2.0 * kPi * config.bandwidth_hz / omega3db;
}

ClosedLoopAxis::ClosedLoopAxis(const AxisLoopConfig& config, double period_s, double kc_over_jeq)
  : wn_(naturalFrequencyForBandwidth(config))
  , zeta_(config.damping)
  , p_(config.pole_ratio * wn_)
  , kc_over_jeq_(kc_over_jeq)
{
  // State (θ, θ'/ωn, η): θ'' = ωn²(η − θ) − 2ζωn θ', η' = p(u − η).
  Eigen::MatrixXd a(3, 3);
  a << 0.0, wn_, 0.0,                 //
      -wn_, -2.0 * zeta_ * wn_, wn_,  //
      0.0, 0.0, -p_;
  Eigen::MatrixXd b(3, 1);
  b << 0.0, 0.0, p_;
  const FohDiscretisation d = discretiseFoh(a, b, period_s);
  ad_ = d.phi;
  // η obeys the real pole alone: these are 0 mathematically (any residue of the Padé solve is
  // rounding) and step() does not read them.
  ad_(2, 0) = 0.0;
  ad_(2, 1) = 0.0;
  g_ = d.gamma2.col(0) - Eigen::Vector3d(1.0, 0.0, 1.0);
  current_row_ = (wn_ * wn_ / kc_over_jeq_) * Eigen::Vector3d(-1.0, -2.0 * zeta_, 1.0);
}

void ClosedLoopAxis::reset(double position_rad)
{
  xi_.setZero();
  u_prev_ = position_rad;
  primed_ = true;
}

AxisModel::Output ClosedLoopAxis::step(double setpoint_rad, double /*setpoint_velocity*/,
                                       double /*setpoint_acceleration*/)
{
  if (!primed_)
  {
    reset(setpoint_rad);
  }
  const double du = setpoint_rad - u_prev_;
  const double x0 = xi_[0], x1 = xi_[1], x2 = xi_[2];
  xi_[0] = ad_(0, 0) * x0 + ad_(0, 1) * x1 + ad_(0, 2) * x2 + g_[0] * du;
  xi_[1] = ad_(1, 0) * x0 + ad_(1, 1) * x1 + ad_(1, 2) * x2 + g_[1] * du;
  xi_[2] = ad_(2, 2) * x2 + g_[2] * du;  // η is the real pole alone: Φ(2,0) = Φ(2,1) = 0 exactly
  u_prev_ = setpoint_rad;
  Output out;
  out.position = setpoint_rad + xi_[0];
  out.velocity = wn_ * xi_[1];
  // θ'' = ωn²(η − θ) − 2ζωn θ' = ωn²(ξ2 − ξ0 − 2ζ ξ1) (the input cancels in η − θ), i = θ''/(Kc/Jeq).
  out.current = current_row_.dot(xi_);
  return out;
}

double ClosedLoopAxis::lowFrequencyDelay() const
{
  return 2.0 * zeta_ / wn_ + 1.0 / p_;
}

std::unique_ptr<AxisModel> makeAxisModel(const ServoConfig& config, int axis, double period_s)
{
  config.validate();
  if (!(period_s > 0.0) || !std::isfinite(period_s))
  {
    std::ostringstream msg;
    msg << "servo: period_s must be > 0 (got " << period_s << ")";
    throw ConfigError(msg.str());
  }
  if (axis != 0 && axis != 1)
  {
    throw ConfigError("servo: axis must be 0 (x) or 1 (y) (got " + std::to_string(axis) + ")");
  }
  const AxisLoopConfig& loop = axis == 0 ? config.x : config.y;
  const char* name = axis == 0 ? "x" : "y";
  if (config.model == "cascade")
  {
    if (config.position_controller == "hinf")
    {
      const HinfDesign design = designHinfController(loop.plant, loop.gains, config.hinf);
      return std::make_unique<CascadeAxis>(loop, period_s, config.controller_rate_hz,
                                           config.feedforward_derivatives == "differentiate",
                                           config.voltage_feedforward, &design);
    }
    return std::make_unique<CascadeAxis>(loop, period_s, config.controller_rate_hz,
                                         config.feedforward_derivatives == "differentiate", config.voltage_feedforward);
  }
  // The first-order hold assumes the setpoint is smooth at the sample rate; a loop faster than a
  // fifth of the sample rate would make that assumption (not the discretisation) the error.
  const double limit_hz = 0.2 / period_s;
  if (!(loop.bandwidth_hz < limit_hz))
  {
    std::ostringstream msg;
    msg << "servo." << name << ".bandwidth_hz must be < 0.2 / period_s = " << limit_hz << " (got " << loop.bandwidth_hz
        << ")";
    throw ConfigError(msg.str());
  }
  return std::make_unique<ClosedLoopAxis>(loop, period_s, config.kc_over_jeq);
}

double axisLowFrequencyDelay(const AxisModel& model)
{
  if (const auto* c = dynamic_cast<const CascadeAxis*>(&model))
  {
    return c->lowFrequencyDelay();
  }
  if (const auto* c = dynamic_cast<const ClosedLoopAxis*>(&model))
  {
    return c->lowFrequencyDelay();
  }
  throw NumericalError("axisLowFrequencyDelay: unknown axis model");
}

GalvoServo::GalvoServo(const ServoConfig& config, double period_s)
  : config_(config)
  , period_s_(period_s)
{
  for (int a = 0; a < 2; ++a)
  {
    axes_[a] = makeAxisModel(config_, a, period_s_);
    closed_loop_[a] = dynamic_cast<ClosedLoopAxis*>(axes_[a].get());
    cascade_[a] = dynamic_cast<CascadeAxis*>(axes_[a].get());
    delay_[a] = axisLowFrequencyDelay(*axes_[a]);
  }
}

void GalvoServo::reset(const Eigen::Vector2d& position)
{
  for (int a = 0; a < 2; ++a)
  {
    axes_[a]->reset(position[a]);
  }
}

JointChunk GalvoServo::process(const SetpointChunk& setpoint)
{
  if (std::abs(setpoint.period_s - period_s_) > 1e-12 * period_s_)
  {
    std::ostringstream msg;
    msg << "servo: setpoint chunk period_s (got " << setpoint.period_s << ") differs from the servo period "
        << period_s_;
    throw ConfigError(msg.str());
  }
  JointChunk out;
  out.first_index = setpoint.first_index;
  out.period_s = setpoint.period_s;
  const std::size_t n = setpoint.samples.size();
  out.samples.resize(n);
  if (closed_loop_[0] != nullptr && closed_loop_[1] != nullptr)
  {
    // Both axes closed-loop: one sample-major loop, the two independent recursions interleave, and
    // the final class makes the calls direct (inlined).
    stepBoth(*closed_loop_[0], *closed_loop_[1], setpoint, out);
    return out;
  }
  if (cascade_[0] != nullptr && cascade_[1] != nullptr)
  {
    // Both axes in the lanes of one vector (bit-identical to stepping them one by one).
    CascadeAxis::stepPair(*cascade_[0], *cascade_[1], setpoint.samples.data(), n, out.samples.data());
    return out;
  }
  for (int a = 0; a < 2; ++a)
  {
    for (std::size_t k = 0; k < n; ++k)
    {
      const SetpointSample& s = setpoint.samples[k];
      const AxisModel::Output o = axes_[a]->step(s.position[a], s.velocity[a], s.acceleration[a]);
      JointSample& j = out.samples[k];
      j.position[a] = o.position;
      j.velocity[a] = o.velocity;
      j.current[a] = o.current;
    }
  }
  return out;
}

Eigen::Vector2d GalvoServo::lowFrequencyDelay() const
{
  return delay_;
}
}  // namespace scanhead
