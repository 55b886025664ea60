/// \file nc_interpolator.hpp
/// \brief The NC stage (SPEC §2): the job becomes an NC program (recipe, delays, skywriting:
/// nc_program.hpp), sampled on its exact timeline, through the inverse geometry (Newton or a
/// correction table), the filters (fixed box FIRs with the velocity saturation, or the
/// speed-adaptive filter) and the laser gate (delays, optional power ∝ speed), optionally
/// quantised as an XY2-100 link would. A source: pulled chunk by chunk.
///
/// Fixed filters (the industrial NC): sample n is at t_n = n·Ts; X_inter(t_n) is the program's
/// exact point; Q_inter = IGT(X_inter); Q_filt1 = box_T1(Q_inter); s = rate limit(Q_filt1);
/// Q_filt2 = box_T2(s), with exact derivatives (nc_interpolator.cpp). Adaptive filters: the
/// program's path is filtered in the work plane (adaptive_fir.hpp, delay D) and Q_filt2 =
/// IGT(X_filt2), q̇ = J⁻¹ Ẋ, q̈ = J⁻¹ (Ẍ − J̇ q̇) (the curvature term: 0.05 % of the limits at
/// 6 m/s, 1.8 % at 35 m/s).
/// Laser: \f[ P_n = \mathrm{gate}(t_n - (D - (T_1 + T_2)/2)) \f] (the gate on the command
/// timeline, laser_gate.hpp; D = (T1 + T2)/2 with fixed filters so the shift is 0), times
/// clamp(v / v_programmed, floor, 1) with v = |Ẋ_filt2| in power_mode "speed", or the plane speed of
/// the actual path predicted by running the servo model on the setpoint in power_mode "predicted".
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <limits>
#include <memory>

#include "scanhead/common/chunk.hpp"
#include "scanhead/nc/nc_config.hpp"
#include "scanhead/nc/nc_plan.hpp"
#include "scanhead/nc/nc_program.hpp"
#include "scanhead/nc/nc_stats.hpp"
#include "scanhead/optics/optical_model.hpp"
#include "scanhead/job/recipe.hpp"
#include "scanhead/job/scan_job.hpp"
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
  std::unique_ptr<ServoConfig> servo_model_;  ///< power_mode "predicted" only
  double servo_delay_s_ = std::numeric_limits<double>::quiet_NaN();  ///< of the servo model, if given (NcPlan)
  Eigen::Vector2d joint_gains_ = Eigen::Vector2d::Zero();  ///< rad/m, computed when the limits are used
  std::unique_ptr<State> state_;
  NcStats empty_stats_;
};
}  // namespace scanhead
