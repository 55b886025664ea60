/// \file galvo_plant.hpp
/// \brief One moving-magnet galvanometer as the THESIS models it (SPEC §3): electrical and
/// mechanical dynamics, friction, one flexible mode, driver voltage saturation.
///
/// \f[ U = R i + L \frac{di}{dt} + K_e \omega, \qquad J_{eq}\frac{d\omega_r}{dt} = K_c i - T_f(\omega_r),
///     \qquad T_f = B\omega_r + T_p + T_c\,\mathrm{sgn}(\omega_r) \f]
/// \f[ \frac{\omega}{i} = \frac{K_c}{J_{eq}s + B} + \frac{K_r s}{s^2 + 2\xi_r\omega_{res}s + \omega_{res}^2} \f]
#pragma once

#include <string>

#include <Eigen/Core>

namespace scanhead
{
/// \brief Physical parameters of one galvo, SI units (see config/scanhead.yaml for their sources).
struct GalvoPlantParams
{
  // Defaults: the Y galvo of this project (galvo_params.hpp gives both axes with their sources).
  double resistance_ohm = 1.65;             ///< R [Ω]
  double inductance_h = 2.86e-4;            ///< L [H]
  double torque_constant_nm_per_a = 0.024;  ///< Kc = Ke [N·m/A] = [V·s/rad]
  double inertia_kgm2 = 2.0e-7;             ///< Jeq, rotor + mirror [kg·m²]
  double viscous_nms = 2.0e-6;              ///< B [N·m·s/rad]
  double offset_torque_nm = 1.0e-6;         ///< Tp [N·m] (galvo_params.hpp)
  double coulomb_torque_nm = 2.1e-6;        ///< Tc [N·m] (fitted: galvo_params.hpp)
  double mode_gain = 4800.0;                ///< Kr of the flexible mode [rad/s² per A]
  double mode_damping = 0.02;               ///< ξr
  double mode_frequency_hz = 5500.0;        ///< ωres / 2π [Hz]
  double supply_voltage_v = 30.0;           ///< driver saturation |U| <= this [V]

  /// \throws ConfigError naming "<prefix>.<field>" and the value
  void validate(const std::string& prefix) const;
};

/// \brief Simulates the plant with the voltage held over each advance() call.
///
/// State \f$x = (i,\ \omega_r,\ \theta,\ \tilde q,\ p)\f$: current, rigid rotor speed, mirror angle
/// and the flexible mode realised as \f$\dot{\tilde q} = \omega_{res}p\f$,
/// \f$\dot p = -\omega_{res}\tilde q - 2\xi_r\omega_{res}p + K_r i\f$ (so \f$p/i\f$ is the mode's term of
/// ω/i); the mirror speed is \f$\omega = \omega_r + p\f$, \f$\dot\theta = \omega\f$, and the back-EMF is
/// \f$K_e\omega\f$ (THESIS eq. 2.30). The plant is linear with inputs (U, T_fr), T_fr = Tp + Tc·sgn(ω_r)
/// piecewise constant: each advance is the exact zero-order-hold step
/// \f$x \leftarrow \Phi x + \Gamma (U, T_{fr})\f$ (matrix exponential, cached per step length), which
/// is exact while ω_r keeps its sign.
///
/// Coulomb friction near ω_r = 0 (Karnopp-style stiction, no smoothing band): if the rigid speed
/// changes sign over a step, the step is redone in 10 sub-steps, and that sub-step again in 10
/// (dt/100, 100 ns at 10 µs); in the finest sub-step where the sign changes the rotor sticks
/// (ω_r := 0) if the drive torque \f$|K_c i - T_p|\f$ is within Tc, else it slides on (the friction
/// sign was wrong for part of that sub-step only: velocity error ≤ 2Tc/Jeq × dt/100). A stuck rotor
/// follows the exact dynamics with ω_r ≡ 0 (static friction balances the drive) while
/// \f$|K_c i - T_p| \le T_c\f$ at a step's start and end, else the step is refined the same way and
/// the rotor breaks away in the first finest sub-step that starts with the drive beyond Tc, the
/// friction opposing the drive. A constant current twists the mode statically: θ then includes
/// \f$K_r i/\omega_{res}^2\f$ even while the rotor is stuck. This keeps sgn(0) = 0, the holding behaviour of real dry
/// friction, and no stiff smoothing term that would force tiny steps.
class GalvoPlant
{
public:
  explicit GalvoPlant(const GalvoPlantParams& params);
  /// \brief At rest at \p angle_rad, no current.
  void reset(double angle_rad);
  /// \brief Advances \p dt_s [s] with the voltage \p voltage_v held (saturated to ±supply).
  void advance(double voltage_v, double dt_s);
  double current() const { return x_[0]; }              ///< i [A]
  double velocity() const { return x_[1] + x_[4]; }     ///< ω measured at the mirror, rigid + flexible mode [rad/s]
  double angle() const { return x_[2]; }                ///< θ [rad]
  double rigidVelocity() const { return x_[1]; }        ///< ω_r, rigid rotor [rad/s]
  double modeVelocity() const { return x_[4]; }         ///< p, the flexible mode's share of ω [rad/s]
  double lastVoltage() const { return last_voltage_; }  ///< U applied by the last advance (saturated) [V]
  /// \brief Friction torque Tf = B ω_r + Tp + Tc sgn(ω_r) at the present state [N·m]
  /// (for a stuck rotor, the static friction that balances the drive).
  double frictionTorque() const;
  const GalvoPlantParams& params() const { return params_; }

private:
  friend class CascadeAxis;  ///< steps two plants in lockstep (CascadeAxis::stepPair)
  using State = Eigen::Matrix<double, 5, 1>;
  struct Step
  {
    double dt_s = -1.0;
    Eigen::Matrix<double, 5, 5> phi;  ///< sliding (or ω_r free)
    Eigen::Matrix<double, 5, 2> gamma;
    Eigen::Matrix<double, 5, 5> phi_stuck;    ///< ω_r held at 0 (static friction balances the drive)
    Eigen::Matrix<double, 5, 1> gamma_stuck;  ///< weight of U when stuck
  };
  static constexpr int kLevels = 3;  ///< dt, dt/10, dt/100
  void prepare(Step& step, double dt_s) const;
  /// \brief The steps of the three levels for a step of \p dt_s (recomputed only when it changes).
  void prepareSteps(double dt_s);
  static void apply(const Step& step, State& x, double voltage_v, double friction_nm);
  /// \brief Advances one step of level \p level, refining to the next level where ω_r changes sign
  /// or a stuck rotor breaks away.
  void advanceLevel(int level, double voltage_v);
  double driveTorque(const State& x) const;  ///< Kc i − Tp [N·m]

  GalvoPlantParams params_;
  State x_ = State::Zero();
  Step steps_[kLevels];
  double last_voltage_ = 0.0;
};
}  // namespace scanhead
