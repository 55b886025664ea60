/// \file galvo_plant.cpp
#include "scanhead/servo/galvo_plant.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "scanhead/common/config_check.hpp"
#include "scanhead/common/errors.hpp"
#include "scanhead/servo/foh_discretisation.hpp"

namespace scanhead
{
namespace
{
constexpr double kPi = 3.14159265358979323846;

double sign(double v)
{
  return v > 0.0 ? 1.0 : (v < 0.0 ? -1.0 : 0.0);
}
}  // namespace

void GalvoPlantParams::validate(const std::string& prefix) const
{
  const std::string p = prefix + ".";
  requireSetting(resistance_ohm > 0.0, p + "resistance_ohm", "> 0", resistance_ohm);
  requireSetting(inductance_h > 0.0, p + "inductance_h", "> 0", inductance_h);
  requireSetting(torque_constant_nm_per_a > 0.0, p + "torque_constant_nm_per_a", "> 0", torque_constant_nm_per_a);
  requireSetting(inertia_kgm2 > 0.0, p + "inertia_kgm2", "> 0", inertia_kgm2);
  requireSetting(viscous_nms >= 0.0, p + "viscous_nms", ">= 0", viscous_nms);
  requireSetting(std::isfinite(offset_torque_nm), p + "offset_torque_nm", "finite", offset_torque_nm);
  requireSetting(coulomb_torque_nm >= 0.0, p + "coulomb_torque_nm", ">= 0", coulomb_torque_nm);
  requireSetting(mode_gain >= 0.0, p + "mode_gain", ">= 0", mode_gain);
  requireSetting(mode_damping > 0.0, p + "mode_damping", "> 0", mode_damping);
  requireSetting(mode_frequency_hz > 0.0, p + "mode_frequency_hz", "> 0", mode_frequency_hz);
  requireSetting(supply_voltage_v > 0.0, p + "supply_voltage_v", "> 0", supply_voltage_v);
}

GalvoPlant::GalvoPlant(const GalvoPlantParams& params)
  : params_(params)
{
  params_.validate("plant");
}

void GalvoPlant::reset(double angle_rad)
{
  x_.setZero();
  x_[2] = angle_rad;
  last_voltage_ = 0.0;
}

void GalvoPlant::prepare(Step& step, double dt_s) const
{
  const GalvoPlantParams& p = params_;
  const double wr = 2.0 * kPi * p.mode_frequency_hz;
  const double kc = p.torque_constant_nm_per_a;
  // x = (i, ω_r, θ, q~, p), u = (U, T_fr).
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(5, 5);
  a(0, 0) = -p.resistance_ohm / p.inductance_h;
  a(0, 1) = -kc / p.inductance_h;  // back-EMF Ke ω, Ke = Kc
  a(0, 4) = -kc / p.inductance_h;
  a(1, 0) = kc / p.inertia_kgm2;
  a(1, 1) = -p.viscous_nms / p.inertia_kgm2;
  a(2, 1) = 1.0;
  a(2, 4) = 1.0;
  a(3, 4) = wr;
  a(4, 3) = -wr;
  a(4, 4) = -2.0 * p.mode_damping * wr;
  a(4, 0) = p.mode_gain;
  Eigen::MatrixXd b = Eigen::MatrixXd::Zero(5, 2);
  b(0, 0) = 1.0 / p.inductance_h;
  b(1, 1) = -1.0 / p.inertia_kgm2;
  const FohDiscretisation d = discretiseFoh(a, b, dt_s);
  step.phi = d.phi;
  step.gamma = d.gamma1;
  // Stuck: ω_r ≡ 0 (its row and column removed from the dynamics).
  a.row(1).setZero();
  a.col(1).setZero();
  const FohDiscretisation s = discretiseFoh(a, b.col(0), dt_s);
  step.phi_stuck = s.phi;
  step.gamma_stuck = s.gamma1;
  step.dt_s = dt_s;
}

void GalvoPlant::apply(const Step& step, State& x, double voltage_v, double friction_nm)
{
  const State x0 = x;
  x.noalias() = step.phi * x0;
  x.noalias() += step.gamma.col(0) * voltage_v;
  x.noalias() += step.gamma.col(1) * friction_nm;
}

double GalvoPlant::driveTorque(const State& x) const
{
  return params_.torque_constant_nm_per_a * x[0] - params_.offset_torque_nm;
}

double GalvoPlant::frictionTorque() const
{
  const GalvoPlantParams& p = params_;
  const double drive = driveTorque(x_);
  if (x_[1] == 0.0 && std::abs(drive) <= p.coulomb_torque_nm)
  {
    return drive + p.offset_torque_nm;  // static: balances Kc i
  }
  const double dir = x_[1] != 0.0 ? sign(x_[1]) : sign(drive);
  return p.viscous_nms * x_[1] + p.offset_torque_nm + p.coulomb_torque_nm * dir;
}

void GalvoPlant::advanceLevel(int level, double voltage_v)
{
  const Step& step = steps_[level];
  const double tc = params_.coulomb_torque_nm;
  const double tp = params_.offset_torque_nm;
  const bool finest = level + 1 == kLevels;
  const double w0 = x_[1];
  State trial = x_;
  if (w0 == 0.0)
  {
    const double drive = driveTorque(x_);
    if (std::abs(drive) <= tc)
    {
      trial.noalias() = step.phi_stuck * x_;
      trial.noalias() += step.gamma_stuck * voltage_v;
      trial[1] = 0.0;
      if (finest || std::abs(driveTorque(trial)) <= tc)
      {
        x_ = trial;  // stays stuck over the step
        return;
      }
    }
    else
    {
      apply(step, trial, voltage_v, tp + tc * sign(drive));  // breaks away against the friction
      if (finest || sign(trial[1]) == sign(drive))
      {
        x_ = trial;
        if (sign(x_[1]) == -sign(drive))
          x_[1] = 0.0;
        return;
      }
    }
  }
  else
  {
    apply(step, trial, voltage_v, tp + tc * sign(w0));
    if (sign(trial[1]) == sign(w0))
    {
      x_ = trial;  // no sign change: exact
      return;
    }
    if (finest)
    {
      x_ = trial;
      if (std::abs(driveTorque(x_)) <= tc)
        x_[1] = 0.0;  // stopped and held by static friction
      return;
    }
  }
  for (int j = 0; j < 10; ++j)
  {
    advanceLevel(level + 1, voltage_v);
  }
}

void GalvoPlant::prepareSteps(double dt_s)
{
  if (dt_s == steps_[0].dt_s)
    return;
  double h = dt_s;
  for (Step& s : steps_)
  {
    prepare(s, h);
    h /= 10.0;
  }
}

void GalvoPlant::advance(double voltage_v, double dt_s)
{
  if (!(dt_s > 0.0))
  {
    std::ostringstream msg;
    msg << "GalvoPlant::advance: dt_s must be > 0 (got " << dt_s << ")";
    throw NumericalError(msg.str());
  }
  const double u = std::clamp(voltage_v, -params_.supply_voltage_v, params_.supply_voltage_v);
  last_voltage_ = u;
  prepareSteps(dt_s);
  if (params_.coulomb_torque_nm == 0.0)
  {
    // No Coulomb term: T_fr = Tp constant, the step is exact whatever ω_r does.
    apply(steps_[0], x_, u, params_.offset_torque_nm);
    return;
  }
  advanceLevel(0, u);
}
}  // namespace scanhead
