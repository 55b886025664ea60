/// \file cascade_axis.cpp
#include "scanhead/servo/cascade_axis.hpp"

#include <cmath>
#include <cstring>
#include <sstream>

#include "cascade_controller_update.hpp"
#include "lanes.hpp"
#include "scanhead/common/errors.hpp"
#include "scanhead/servo/hinf/hinf_loops.hpp"
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

using lanes::Double2;
using lanes::Mask2;

/// \brief \p out's i-th double field = (a's i-th, b's i-th) for structs made of doubles only
/// (CascadeControllerCoefficients, CascadeControllerState).
template <template <class> class S>
void zip(S<Double2>& out, const S<double>& a, const S<double>& b)
{
  constexpr std::size_t n = sizeof(S<double>) / sizeof(double);
  static_assert(sizeof(S<double>) == n * sizeof(double) && sizeof(S<Double2>) == n * sizeof(Double2),
                "zip: a struct of doubles only");
  double da[n], db[n];
  Double2 v[n];
  std::memcpy(da, &a, sizeof da);
  std::memcpy(db, &b, sizeof db);
  for (std::size_t i = 0; i < n; ++i)
    v[i] = Double2{da[i], db[i]};
  std::memcpy(&out, v, sizeof v);
}

/// \brief Inverse of zip.
template <template <class> class S>
void unzip(const S<Double2>& in, S<double>& a, S<double>& b)
{
  constexpr std::size_t n = sizeof(S<double>) / sizeof(double);
  double da[n], db[n];
  Double2 v[n];
  std::memcpy(v, &in, sizeof v);
  for (std::size_t i = 0; i < n; ++i)
  {
    da[i] = v[i][0];
    db[i] = v[i][1];
  }
  std::memcpy(&a, da, sizeof da);
  std::memcpy(&b, db, sizeof db);
}
}  // namespace

CascadeAxis::CascadeAxis(const AxisLoopConfig& config, double period_s, double controller_rate_hz, bool differentiate,
                         bool voltage_feedforward, const HinfDesign* hinf)
  : plant_(config.plant)
  , controller_(config.gains, config.plant.inertia_kgm2 / config.plant.torque_constant_nm_per_a,
                1.0 / controller_rate_hz, config.plant.supply_voltage_v, differentiate, config.plant,
                voltage_feedforward, hinf)
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
  delay_s_ = hinf != nullptr
                 ? hinfLowFrequencyDelay(config.plant, config.gains, *hinf, controller_period_s_, voltage_feedforward)
                 : scanhead::lowFrequencyDelay(config.plant, config.gains, controller_period_s_, voltage_feedforward);
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

// Clones: the same SSE2-width lanes; AVX-512's 32 vector registers and three-operand forms spare
// the spills and copies around the recursion (the servo library is built with -ffp-contract=off, so
// no clone fuses a multiply-add: every clone gives the same bits).
__attribute__((target_clones("avx512f", "avx2", "default"))) void CascadeAxis::stepPair(CascadeAxis& x, CascadeAxis& y,
                                                                                        const SetpointSample* setpoint,
                                                                                        std::size_t n, JointSample* out)
{
  const auto scalarStep = [&](std::size_t k) {
    const SetpointSample& s = setpoint[k];
    const Output ox = x.step(s.position[0], s.velocity[0], s.acceleration[0]);
    const Output oy = y.step(s.position[1], s.velocity[1], s.acceleration[1]);
    JointSample& j = out[k];
    j.position = Eigen::Vector2d(ox.position, oy.position);
    j.velocity = Eigen::Vector2d(ox.velocity, oy.velocity);
    j.current = Eigen::Vector2d(ox.current, oy.current);
  };
  std::size_t k = 0;
  if (n > 0 && (!x.primed_ || !y.primed_))
    scalarStep(k++);  // the first call resets at the setpoint
  const bool lockstep = x.ticks_per_sample_ == 1 && y.ticks_per_sample_ == 1 &&
                        x.samples_per_tick_ == y.samples_per_tick_ && x.phase_ == y.phase_ &&
                        x.period_s_ == y.period_s_ && x.controller_.differentiate_ == y.controller_.differentiate_ &&
                        x.controller_.voltage_ff_ == y.controller_.voltage_ff_ && !x.controller_.hinf_ &&
                        !y.controller_.hinf_;
  if (!lockstep)
  {
    for (; k < n; ++k)
      scalarStep(k);
    return;
  }
  if (k == n)
    return;

  // Both plants' sliding step x ← Φx + Γ(U, T_fr) (GalvoPlant::apply), lane 0 = x, lane 1 = y.
  GalvoPlant& px = x.plant_;
  GalvoPlant& py = y.plant_;
  px.prepareSteps(x.period_s_);
  py.prepareSteps(y.period_s_);
  const GalvoPlant::Step& sx = px.steps_[0];
  const GalvoPlant::Step& sy = py.steps_[0];
  Double2 phi[5][5], g_u[5], g_f[5], phis[5][5], g_s[5], st[5];
  for (int i = 0; i < 5; ++i)
  {
    for (int c = 0; c < 5; ++c)
    {
      phi[i][c] = Double2{sx.phi(i, c), sy.phi(i, c)};
      phis[i][c] = Double2{sx.phi_stuck(i, c), sy.phi_stuck(i, c)};
    }
    g_u[i] = Double2{sx.gamma(i, 0), sy.gamma(i, 0)};
    g_f[i] = Double2{sx.gamma(i, 1), sy.gamma(i, 1)};
    g_s[i] = Double2{sx.gamma_stuck(i), sy.gamma_stuck(i)};
    st[i] = Double2{px.x_[i], py.x_[i]};
  }
  const Double2 zero = {0.0, 0.0}, one = {1.0, 1.0};
  const Double2 tp = {px.params_.offset_torque_nm, py.params_.offset_torque_nm};
  const Double2 tc = {px.params_.coulomb_torque_nm, py.params_.coulomb_torque_nm};
  const Double2 kt = {px.params_.torque_constant_nm_per_a, py.params_.torque_constant_nm_per_a};
  const Mask2 no_coulomb = tc == zero;  // T_fr = Tp: every step exact (GalvoPlant::advance)
  CascadeControllerCoefficients<Double2> kc;
  CascadeControllerState<Double2> cs;
  zip(kc, x.controller_.k_, y.controller_.k_);
  zip(cs, x.controller_.s_, y.controller_.s_);
  const bool differentiate = x.controller_.differentiate_, voltage_ff = x.controller_.voltage_ff_;
  Double2 u = {x.voltage_, y.voltage_};
  long long phase = x.phase_;
  const long long m = x.samples_per_tick_;
  GalvoPlant* plants[2] = {&px, &py};

  for (; k < n; ++k)
  {
    const SetpointSample& s = setpoint[k];
    const Double2 theta = st[2], omega = st[1] + st[4], current = st[0];
    JointSample& j = out[k];
    j.position = Eigen::Vector2d(theta[0], theta[1]);
    j.velocity = Eigen::Vector2d(omega[0], omega[1]);
    j.current = Eigen::Vector2d(current[0], current[1]);
    if (phase == 0)
    {
      // The controller's output is saturated already: the plant's own clamp leaves it unchanged.
      u = cascadeControllerUpdate(kc, cs, differentiate, voltage_ff, Double2{s.position[0], s.position[1]},
                                  Double2{s.velocity[0], s.velocity[1]}, Double2{s.acceleration[0], s.acceleration[1]},
                                  theta, omega, current);
    }
    // GalvoPlant::advanceLevel at level 0, both lanes: a moving rotor slides with the friction of
    // its direction; a rotor at rest breaks away against the drive Kc·i − Tp if that exceeds Tc,
    // else it is stuck (ω_r held at 0). A step that would need the finer levels (the speed changes
    // sign, a stuck rotor's drive leaves ±Tc) is redone by that plant's scalar code below.
    const Double2 w0 = st[1];
    const Double2 drive = kt * st[0] - tp;
    const Mask2 moving = w0 != zero;
    const Double2 dir = moving ? (w0 > zero ? one : -one) : (drive > zero ? one : -one);
    const Double2 f = no_coulomb ? tp : tp + tc * dir;
    Double2 t[5];
    // Φx as Eigen's fixed 5×5 product forms it (rows 0–3 in SSE2 packets, left to right; row 4 by
    // its unrolled reduction), then + Γ_U·U, then + Γ_T·T_fr (GalvoPlant::apply).
    for (int i = 0; i < 4; ++i)
    {
      const Double2 phix =
          (((phi[i][0] * st[0] + phi[i][1] * st[1]) + phi[i][2] * st[2]) + phi[i][3] * st[3]) + phi[i][4] * st[4];
      t[i] = (phix + g_u[i] * u) + g_f[i] * f;
    }
    {
      const Double2 phix =
          (phi[4][0] * st[0] + phi[4][1] * st[1]) + (phi[4][2] * st[2] + (phi[4][3] * st[3] + phi[4][4] * st[4]));
      t[4] = (phix + g_u[4] * u) + g_f[4] * f;
    }
    // Exact while ω_r keeps the sign it starts with (or breaks away to).
    Mask2 ok = no_coulomb | (((dir > zero) & (t[1] > zero)) | ((dir < zero) & (t[1] < zero)));
    const Mask2 stuck = ~no_coulomb & ~moving & (lanes::magnitude(drive) <= tc);
    if (lanes::laneBits(stuck) != 0)
    {
      // Stuck: x ← Φs x + Γs U with ω_r := 0, kept if the drive stays within ±Tc at the step's end (a rotor at rest:
      // the branch changes only where the rotor stops or breaks away, rarely enough to be predicted).
      Double2 ts[5];
      for (int i = 0; i < 4; ++i)
        ts[i] = (((phis[i][0] * st[0] + phis[i][1] * st[1]) + phis[i][2] * st[2]) + phis[i][3] * st[3]) +
                phis[i][4] * st[4] + g_s[i] * u;
      ts[4] = (phis[4][0] * st[0] + phis[4][1] * st[1]) +
              (phis[4][2] * st[2] + (phis[4][3] * st[3] + phis[4][4] * st[4])) + g_s[4] * u;
      ts[1] = zero;
      const Mask2 held = lanes::magnitude(kt * ts[0] - tp) <= tc;
      for (int i = 0; i < 5; ++i)
        t[i] = stuck ? ts[i] : t[i];
      ok = stuck ? held : ok;
    }
    const int ok_lanes = lanes::laneBits(ok);
    if (ok_lanes == 3)
    {
      for (int i = 0; i < 5; ++i)
        st[i] = t[i];
    }
    else
    {
      for (int lane = 0; lane < 2; ++lane)
      {
        if (ok_lanes & (1 << lane))
        {
          for (int i = 0; i < 5; ++i)
            st[i][lane] = t[i][lane];
          continue;
        }
        GalvoPlant& p = *plants[lane];
        for (int i = 0; i < 5; ++i)
          p.x_[i] = st[i][lane];
        p.advanceLevel(0, u[lane]);
        for (int i = 0; i < 5; ++i)
          st[i][lane] = p.x_[i];
      }
    }
    if (++phase == m)
      phase = 0;
  }

  for (int i = 0; i < 5; ++i)
  {
    px.x_[i] = st[i][0];
    py.x_[i] = st[i][1];
  }
  px.last_voltage_ = u[0];
  py.last_voltage_ = u[1];
  x.voltage_ = u[0];
  y.voltage_ = u[1];
  x.phase_ = y.phase_ = phase;
  unzip(cs, x.controller_.s_, y.controller_.s_);
}
}  // namespace scanhead
