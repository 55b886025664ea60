/// \file cascade_axis.cpp
#include "scanhead/servo/cascade_axis.hpp"

#include <cmath>
#include <sstream>

#include "scanhead/common/errors.hpp"
#include "scanhead/servo/loop_analysis.hpp"

namespace scanhead
{
namespace
{
/// \brief n if x is within 1e-9 of the whole number n ≥ 1, else 0.
int wholeRatio(double x)
{
  const double n = std::round(x);
  return (n >= 1.0 && std::abs(x - n) <= 1e-9 * n) ? static_cast<int>(n) : 0;
}
}  // namespace

CascadeAxis::CascadeAxis(const AxisLoopConfig& config, double period_s, double controller_rate_hz, bool differentiate,
                         bool voltage_feedforward)
  : plant_(config.plant)
  , controller_(config.gains, config.plant.inertia_kgm2 / config.plant.torque_constant_nm_per_a,
                1.0 / controller_rate_hz, config.plant.supply_voltage_v, differentiate, config.plant,
                voltage_feedforward)
  , period_s_(period_s)
  , controller_period_s_(1.0 / controller_rate_hz)
{
  const double ratio = controller_period_s_ / period_s_;
  samples_per_tick_ = wholeRatio(ratio);
  ticks_per_sample_ = wholeRatio(1.0 / ratio);
  if (samples_per_tick_ == 0 && ticks_per_sample_ == 0)
  {
    std::ostringstream msg;
    msg << "servo.controller_rate_hz: the controller period " << controller_period_s_
        << " s must be a whole multiple or a whole fraction of the sample period " << period_s_ << " s (got "
        << controller_rate_hz << ")";
    throw ConfigError(msg.str());
  }
  if (samples_per_tick_ == 0)
  {
    samples_per_tick_ = 1;
  }
  else
  {
    ticks_per_sample_ = 1;
  }
  // The delay of the linear model: exact derivatives or the filtered ones, same transfer function.
  delay_s_ = scanhead::lowFrequencyDelay(config.plant, config.gains, controller_period_s_, voltage_feedforward);
}

void CascadeAxis::reset(double position_rad)
{
  plant_.reset(position_rad);
  controller_.reset(position_rad);
  phase_ = 0;
  voltage_ = 0.0;
  primed_ = true;
}

AxisModel::Output CascadeAxis::step(double setpoint_rad, double setpoint_velocity, double setpoint_acceleration)
{
  if (!primed_)
  {
    reset(setpoint_rad);
  }
  Output out;
  out.position = plant_.angle();
  out.velocity = plant_.velocity();
  out.current = plant_.current();
  if (ticks_per_sample_ == 1)
  {
    if (phase_ == 0)
    {
      voltage_ = controller_.update(setpoint_rad, setpoint_velocity, setpoint_acceleration, out.position, out.velocity,
                                    out.current);
    }
    plant_.advance(voltage_, period_s_);
    if (++phase_ == samples_per_tick_)
    {
      phase_ = 0;
    }
    return out;
  }
  for (int j = 0; j < ticks_per_sample_; ++j)
  {
    const double tau = j * controller_period_s_;
    const double ref = setpoint_rad + tau * (setpoint_velocity + 0.5 * tau * setpoint_acceleration);
    const double vel = setpoint_velocity + tau * setpoint_acceleration;
    voltage_ = controller_.update(ref, vel, setpoint_acceleration, plant_.angle(), plant_.velocity(), plant_.current());
    plant_.advance(voltage_, controller_period_s_);
  }
  return out;
}
}  // namespace scanhead
