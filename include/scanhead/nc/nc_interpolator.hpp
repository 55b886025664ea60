/// \file nc_interpolator.hpp
/// \brief The NC stage (SPEC §2): the job becomes an NC program (recipe, delays, skywriting:
/// nc_program.hpp), sampled on its exact timeline, through the inverse geometry (Newton or a
/// correction table), the filters (fixed box FIRs with the velocity saturation, or the
/// speed-adaptive filter) and the laser gate (delays, optional power ∝ speed), optionally
/// quantised as an XY2-100 link would. A source: pulled chunk by chunk.
///
/// Fixed filters (the industrial NC): sample n is at t_n = n·Ts; X_inter(t_n) is the program's
/// exact point; Q_inter = IGT(X_inter); Q_filt1 = box_T1(Q_inter); s = rate limit(Q_filt1);
/// Q_filt2 = box_T2(s), with exact derivatives (see Derivatives below). Adaptive filters: the
/// program's path is filtered in the work plane (adaptive_fir.hpp, delay D) and Q_filt2 =
/// IGT(X_filt2), q̇ = J⁻¹ Ẋ, q̈ = J⁻¹ (Ẍ − J̇ q̇) (the curvature term: 0.05 % of the limits at
/// 6 m/s, 1.8 % at 35 m/s).
/// Laser: \f[ P_n = \mathrm{gate}(t_n - (D - (T_1 + T_2)/2)) \f] (the gate on the command
/// timeline, laser_gate.hpp; D = (T1 + T2)/2 with fixed filters so the shift is 0), times
/// clamp(v / v_programmed, floor, 1) with v = |Ẋ_filt2| in power_mode "speed", or the plane speed of
/// the actual path predicted by running the servo model on the setpoint in power_mode "predicted".
///
/// \par IGT
/// Newton on the ray trace to its tolerance (OpticalModel::inverse's criterion:
/// \f$|x - h(q)| \le\f$ newton_tolerance_m, q within the joint limits), a chunk at a time: every
/// sample's IGT point from \f$q^0\f$ = a bicubic 65 × 65 correction table over the field (error
/// < 0.05 nm on the plane, correction_table.hpp), one simplified Newton step
/// \f[ q^1 = q^0 + M\,(x - h(q^0)) \f] with M the nodes' exact \f$J^{-1}\f$ interpolated
/// bilinearly (contraction \f$|I - MJ| \lesssim 10^{-4}\f$, so \f$|x - h(q^1)| \sim 10^{-16}\f$ m),
/// both residuals traced in blocks (OpticalModel::traceBlock). A sample neither accepts goes to
/// OpticalModel::inverse from \f$q^1\f$ (retried from q = 0). Each sample's solution depends on
/// its point only, never on the chunking. If the optics cannot reach a node of that table, each
/// sample is warm-started instead from the linear extrapolation \f$2 q_{n-1} - q_{n-2}\f$ of the
/// previous solutions (retried from 0). A sample whose point equals the previous one reuses its
/// solution (holds, the tail). Or the correction table (correction_table.hpp), which needs no guess.
///
/// \par Derivatives of Q_filt2 with fixed filters (the setpoint velocity and acceleration)
/// - velocity: exact. Q_filt2(t) is the box mean over T2 of the piecewise-linear signal s(t)
///   through the saturated samples, so
///   \f[ \frac{dQ_{filt2}}{dt}(t_n) = \frac{s_n - s(t_n - T_2)}{T_2} \f]
///   with s linearly interpolated at the fractional delay (BoxFilter::derivative). T2 = 0: the
///   velocity of s below.
/// - velocity of s (after the saturation): where the axis is not limited, the exact derivative
///   of the FIR T1 output, \f$(q_n - q(t_n - T_1))/T_1\f$ (T1 = 0: backward difference of
///   Q_inter, the left derivative of its linear interpolation); where limited,
///   ±max_joint_speed_radps.
/// - acceleration: the same exact box derivative applied to the velocity samples of s read as a
///   piecewise-linear signal, \f$(\dot s_n - \dot s(t_n - T_2))/T_2\f$ (T2 = 0: backward
///   difference of \f$\dot s\f$). This is the exact acceleration of box_T2(box_T1(Q_inter)) up to
///   the linear interpolation of the T1 velocity between samples, which differs from the true
///   (kinked) velocity only in the periods containing a kink (\f$O(T_s^2 a / T_2)\f$ on the
///   integrated velocity); it reproduces the rectangle (T1) ⊗ box (T2) trapezoid of SPEC §2.3.
///
/// Q_filt1's acceleration (debug) is the same box derivative of the Q_inter velocity over T1.
///
/// \par Power ∝ speed
/// The speed of the filtered path is taken in the work plane, by running the same box filters on
/// X_inter (fixed) or from the adaptive filter: filtering in joint or task space gives the same
/// path to < 0.1 µm (SPEC §2, NC §3), and the plane speed is what deposits energy.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <limits>
#include <memory>

#include "scanhead/common/chunk.hpp"
#include "scanhead/job/recipe.hpp"
#include "scanhead/job/scan_job.hpp"
#include "scanhead/nc/nc_config.hpp"
#include "scanhead/nc/nc_plan.hpp"
#include "scanhead/nc/nc_program.hpp"
#include "scanhead/nc/nc_stats.hpp"
#include "scanhead/optics/optical_model.hpp"
#include "scanhead/servo/servo_config.hpp"

namespace scanhead
{
struct NcOutput
{
  SetpointChunk setpoint;
  LaserChunk laser;
  NcDebugChunk debug;  ///< empty unless NcConfig::debug
};

class NcInterpolator
{
public:
  /// \param[in] optics used for the inverse geometric transform (kept by reference: must outlive this)
  /// \param[in] servo_model the servo behind the NC: its delay goes into the plan
  ///            (NcPlan::servo_delay_s, NaN without it), and power_mode "predicted" runs it on the
  ///            setpoint (copied; may be null otherwise)
  /// \throws ConfigError on a bad config; InputError / NumericalError on a bad table file or an
  /// optics that cannot reach the table's nodes
  NcInterpolator(const NcConfig& config, const Recipe& recipe, const OpticalModel& optics,
                 const ServoConfig* servo_model = nullptr);
  /// \brief The job's own speeds and powers, laser delays (T1 + T2)/2 (the laser follows Q_filt2).
  NcInterpolator(const NcConfig& config, const OpticalModel& optics);
  ~NcInterpolator();

  /// \brief Resets all state and loads a validated job. \throws NumericalError if a point is unreachable
  void start(const Job& job);

  /// \brief Next at most \p max_samples samples (fewer at the end of the job); first_index and
  /// period_s set on every chunk. Chunk sizes do not change the streams (bit-identical).
  /// \throws NumericalError if a sampled point is unreachable; the job is then abandoned
  NcOutput process(std::size_t max_samples);

  bool done() const;
  /// \brief Samples the whole job produces, tail included (NcPlan::total_samples). 0 before start().
  std::uint64_t totalSamples() const;
  double pathDuration() const;  ///< duration of the NC program (Σ L/v + delays + skywriting) [s]
  const NcStats& stats() const;
  /// \brief The program of the job given to start(). \pre start() was called (throws std::logic_error otherwise)
  const NcProgram& program() const;
  /// \brief The plan of the job given to start() (nc_plan.hpp). \pre start() was called (throws
  /// std::logic_error otherwise)
  const NcPlan& plan() const;
  const NcConfig& config() const { return config_; }

private:
  struct State;
  struct Igt;
  NcConfig config_;
  Recipe recipe_;
  const OpticalModel& optics_;
  std::unique_ptr<Igt> igt_;
  std::unique_ptr<ServoConfig> servo_model_;                         ///< power_mode "predicted" only
  double servo_delay_s_ = std::numeric_limits<double>::quiet_NaN();  ///< of the servo model, if given (NcPlan)
  Eigen::Vector2d joint_gains_ = Eigen::Vector2d::Zero();            ///< rad/m, computed when the limits are used
  std::unique_ptr<State> state_;
  NcStats empty_stats_;
};
}  // namespace scanhead
