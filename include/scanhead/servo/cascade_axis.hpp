/// \file cascade_axis.hpp
/// \brief One galvo axis as SPEC §3 models it: the plant under its discrete cascade controller.
#pragma once

#include "scanhead/servo/cascade_controller.hpp"
#include "scanhead/servo/galvo_plant.hpp"
#include "scanhead/servo/galvo_servo.hpp"
#include "scanhead/servo/servo_config.hpp"

namespace scanhead
{
/// \brief GalvoPlant + CascadeController, stepped at the sample period Ts with the controller at
/// its own period Tc (a whole multiple m·Ts or a whole fraction Ts/n).
///
/// Timing: the controller samples θ, ω, i at its instants t_j = j·Tc and holds its voltage until
/// t_{j+1} (zero-order hold; no computation delay), the plant is integrated exactly in between.
/// step(u_k) returns the plant state at t_k (the measurement at the setpoint's instant), then
/// advances the plant to t_{k+1}; with Tc = m·Ts the controller runs at the samples k ≡ 0 (mod m)
/// counted from reset and uses that sample's setpoint; with Tc = Ts/n, the n controller instants
/// inside [t_k, t_{k+1}) use the setpoint extrapolated with its NC derivatives,
/// \f$\theta_{ref} + \dot\theta_{ref}\tau + \ddot\theta_{ref}\tau^2/2\f$.
/// The reported current is the plant's current, the velocity the mirror's (rigid + mode).
class CascadeAxis final : public AxisModel
{
public:
  /// \throws ConfigError if Tc is neither a whole multiple nor a whole fraction of \p period_s
  /// \param[in] config  validated axis config (plant, gains)
  /// \param[in] period_s  sample period Ts [s]
  /// \param[in] controller_rate_hz  1/Tc [Hz]
  /// \param[in] differentiate  feedforward from differentiated setpoint (else NC derivatives)
  /// \param[in] voltage_feedforward  add U_ff = R i_ff + L di_ff/dt + Ke ω_ff (cascade_controller.hpp)
  /// \param[in] hinf  the H∞ position controller (servo.position_controller: hinf), or null for the PD + speed PI
  CascadeAxis(const AxisLoopConfig& config, double period_s, double controller_rate_hz, bool differentiate,
              bool voltage_feedforward = true, const HinfDesign* hinf = nullptr);
  void reset(double position_rad) override;
  /// \brief Plant state at the instant of \p setpoint_rad; if reset() was never called, the
  /// first call resets the axis at rest at \p setpoint_rad.
  Output step(double setpoint_rad, double setpoint_velocity, double setpoint_acceleration) override;
  /// \brief −d arg(θ/θref)/dω at 0 of the linear model (feedforward included, sampling delay
  /// Tc/2): the steady lag of a ramp [s]; ≈ 0 with K1 = K2 = 1 (θ/θref = 1 + O(s²)).
  double lowFrequencyDelay() const { return delay_s_; }
  const GalvoPlant& plant() const { return plant_; }
  const CascadeController& controller() const { return controller_; }
  double voltage() const { return voltage_; }  ///< voltage held now [V]

  /// \brief Steps \p x and \p y over the same \p n setpoint samples (axis 0 and 1 of each) and
  /// writes \p out[k] (position, velocity, current of both axes): the two axes run in the lanes of
  /// one SSE2 vector, sliding steps of the plants in lockstep, each lane doing the scalar step's
  /// operations in the same order, so outputs and states are bit-identical to calling x.step() and
  /// y.step() per sample. A plant step where the rigid speed is 0 or changes sign (friction
  /// refinement) is taken by that plant's scalar code. Falls back to step() per sample when the
  /// axes are not in lockstep (controller faster than the samples, phases, periods or modes differ) or run the
  /// H∞ position controller.
  static void stepPair(CascadeAxis& x, CascadeAxis& y, const SetpointSample* setpoint, std::size_t n, JointSample* out);

private:
  GalvoPlant plant_;
  CascadeController controller_;
  double period_s_;
  double controller_period_s_;
  int samples_per_tick_ = 1;  ///< m (≥ 1) when Tc = m·Ts
  int ticks_per_sample_ = 1;  ///< n (≥ 1) when Tc = Ts/n
  long long phase_ = 0;       ///< samples since reset modulo m
  double voltage_ = 0.0;
  double delay_s_ = 0.0;
  bool primed_ = false;
};
}  // namespace scanhead
