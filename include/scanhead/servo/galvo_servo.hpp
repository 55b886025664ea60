/// \file galvo_servo.hpp
/// \brief The servo stage: one model per axis turns the setpoint stream into measured joints.
#pragma once

#include <array>
#include <memory>

#include "scanhead/common/chunk.hpp"
#include "scanhead/servo/servo_config.hpp"

namespace scanhead
{
class CascadeAxis;

/// \brief One axis of the servo, stepped once per sample (the interface a cascade model implements).
class AxisModel
{
public:
  struct Output
  {
    double position = 0.0;  ///< [rad]
    double velocity = 0.0;  ///< [rad/s]
    double current = 0.0;   ///< [A]
  };
  virtual ~AxisModel() = default;
  /// \brief At rest at \p position_rad.
  virtual void reset(double position_rad) = 0;
  /// \brief Advances one period from the setpoint sample of the current instant.
  virtual Output step(double setpoint_rad, double setpoint_velocity, double setpoint_acceleration) = 0;
};

/// \brief Closed-loop third-order axis, discretised exactly (zero-order hold on the input
/// interpolated linearly between samples: first-order hold).
///
/// Model (first fidelity of SPEC §3, the whole position loop seen from its setpoint):
/// \f[ \frac{\theta}{\theta_{ref}}(s) = \frac{\omega_n^2\,p}{(s^2 + 2\zeta\omega_n s + \omega_n^2)(s + p)}, \f]
/// unit DC gain, realised as a cascade: the real pole first, \f$\dot\eta = p(\theta_{ref} - \eta)\f$,
/// then the pole pair, \f$\ddot\theta = \omega_n^2(\eta - \theta) - 2\zeta\omega_n\dot\theta\f$.
/// State \f$x = (\theta,\ \dot\theta/\omega_n,\ \eta)\f$ (velocity scaled by 1/ωn so that A·Ts is
/// well balanced for the Padé exponential). The setpoint is taken linear between samples
/// (first-order hold) and the step is exact: with \f$\Delta u_k = u_k - u_{k-1}\f$,
/// \f[ x_k = \Phi x_{k-1} + \Gamma_1 u_{k-1} + \Gamma_2 \Delta u_k \f]
/// (see foh_discretisation.hpp). The state is stored as the deviation
/// \f$\xi = x - (1, 0, 1)\,u\f$ from the equilibrium of the last input, where the recurrence reads
/// \f$\xi_k = \Phi\,\xi_{k-1} + (\Gamma_2 - (1,0,1)^T)\,\Delta u_k\f$ (because Φe + Γ1 = e):
/// a constant setpoint at the rest position leaves the output bit-exactly unchanged, and
/// large absolute angles cost no precision.
///
/// Outputs at the instant of the setpoint sample u_k: position θ, velocity \f$\dot\theta\f$ (a
/// state, the exact derivative), and motor current \f$i = \ddot\theta / (K_c/J_{eq})\f$ with
/// \f$\ddot\theta\f$ exact from the state. This model has **no motor**: the current is the rigid
/// inertia's share only (no friction, no flexible mode, no back-EMF); the cascade model of SPEC §3
/// replaces it. The setpoint velocity and acceleration (feedforward inputs) are unused here.
class ClosedLoopAxis final : public AxisModel
{
public:
  /// \param[in] config  bandwidth, damping, pole ratio (validated by the caller)
  /// \param[in] period_s  sample period Ts [s]
  /// \param[in] kc_over_jeq  Kc/Jeq [rad/s²/A], only to report the current
  ClosedLoopAxis(const AxisLoopConfig& config, double period_s, double kc_over_jeq);
  void reset(double position_rad) override;
  /// \brief Output y_k at the instant of \p setpoint_rad = u_k, from the state at k-1, u_{k-1} and u_k.
  /// If reset() was never called, the first call resets the axis at rest at \p setpoint_rad.
  Output step(double setpoint_rad, double setpoint_velocity, double setpoint_acceleration) override;

  double naturalFrequency() const { return wn_; }  ///< ωn [rad/s]
  double realPole() const { return p_; }           ///< p [rad/s]
  /// \brief Low-frequency delay d(-phase)/dω at 0 = 2ζ/ωn + 1/p [s].
  ///
  /// \f[ \arg H(j\omega) = -\arctan\frac{2\zeta\omega/\omega_n}{1 - \omega^2/\omega_n^2}
  ///     - \arctan\frac{\omega}{p} \Rightarrow -\frac{d\arg H}{d\omega}\Big|_0 = \frac{2\zeta}{\omega_n} + \frac{1}{p},
  ///     \f]
  /// also the first moment of the impulse response, so a ramp of slope v is followed with the
  /// steady error v × this delay (H(s) = 1 − τ s + O(s²)).
  double lowFrequencyDelay() const;

private:
  double wn_ = 0, zeta_ = 0, p_ = 0, kc_over_jeq_ = 0;
  Eigen::Matrix3d ad_ = Eigen::Matrix3d::Identity();       ///< Φ, state transition over one period
  Eigen::Vector3d g_ = Eigen::Vector3d::Zero();            ///< Γ2 − (1,0,1): weight of Δu_k on ξ
  Eigen::Vector3d current_row_ = Eigen::Vector3d::Zero();  ///< ωn²/(Kc/Jeq)·(−1, −2ζ, 1): current from ξ [A]
  Eigen::Vector3d xi_ = Eigen::Vector3d::Zero();           ///< deviation state ξ = x − (1,0,1)·u_prev_
  double u_prev_ = 0.0;                                    ///< last setpoint sample [rad]
  bool primed_ = false;
};

/// \brief ωn [rad/s] that puts the -3 dB frequency of the normalised loop at \p config.bandwidth_hz.
///
/// The normalised response \f$H_0(j\Omega) = r / ((1 - \Omega^2 + 2j\zeta\Omega)(j\Omega + r))\f$,
/// \f$\Omega = \omega/\omega_n\f$, \f$r\f$ = pole_ratio, depends only on ζ and r: its lowest
/// \f$\Omega_{3dB}\f$ with \f$|H_0|^2 = 1/2\f$ is bracketed by a geometric scan and refined by
/// bisection, then \f$\omega_n = 2\pi f_{bw} / \Omega_{3dB}\f$.
/// \throws NumericalError if no crossing is found (cannot happen for valid configs)
double naturalFrequencyForBandwidth(const AxisLoopConfig& config);

/// \brief The axis model \p config selects: servo.model "cascade" (CascadeAxis: GalvoPlant under
/// the cascade controller, SPEC §3) or "closed_loop_3rd_order" (ClosedLoopAxis).
/// \param[in] axis  0 = x (galvo_x), 1 = y (galvo_y)
/// \param[in] period_s  sample period Ts [s]
/// \throws ConfigError on an invalid config or period, an axis not 0/1, bandwidth_hz ≥ 0.2 / period_s
/// (closed_loop_3rd_order), a controller period neither a whole multiple nor a whole fraction of Ts (cascade)
std::unique_ptr<AxisModel> makeAxisModel(const ServoConfig& config, int axis, double period_s);

/// \brief Low-frequency delay of an axis made by makeAxisModel (ClosedLoopAxis or CascadeAxis) [s].
double axisLowFrequencyDelay(const AxisModel& model);

/// \brief Servo stage of the chain: per-axis models (X = galvo_x, Y = galvo_y) over the setpoint stream.
class GalvoServo
{
public:
  /// \throws ConfigError as makeAxisModel
  GalvoServo(const ServoConfig& config, double period_s);
  /// \brief At rest at \p position (both axes) before a job.
  void reset(const Eigen::Vector2d& position);
  /// \brief Joint states at the instants of the setpoint samples; same first_index and period_s.
  /// State is kept across calls (chunk invariant).
  /// \throws ConfigError if the chunk's period_s differs from the servo's
  JointChunk process(const SetpointChunk& setpoint);
  /// \brief Delay of the actual path behind the setpoint at low frequency, per axis [s]
  /// (cascade: ≈ 0 with the feedforward, see CascadeAxis::lowFrequencyDelay).
  Eigen::Vector2d lowFrequencyDelay() const;

private:
  ServoConfig config_;
  double period_s_;
  std::array<std::unique_ptr<AxisModel>, 2> axes_;
  std::array<ClosedLoopAxis*, 2> closed_loop_{
      {nullptr, nullptr}};  ///< the same axes when closed-loop (final: calls devirtualised), else null
  std::array<CascadeAxis*, 2> cascade_{{nullptr, nullptr}};  ///< the same axes when cascade, else null
  Eigen::Vector2d delay_;
};
}  // namespace scanhead
