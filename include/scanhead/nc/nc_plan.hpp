/// \file nc_plan.hpp
/// \brief The NC's plan of a job, as a value: what the NC will run (the program: timeline, laser
/// gate, holds), how its output lags the command (filter delay, gate shift), where it starts, how
/// many samples it produces, and how far the servo lags the setpoint.
///
/// Computed once when the NC starts a job (NcInterpolator::start); sampling consumes it, and the
/// downstream stages read it (corner times, laser windows, delays, plot decimation) instead of
/// building an NC or a servo of their own: one plan, so the NC and the energy stage cannot
/// disagree on the timing of a corner.
///
/// Sample count (SPEC §2.1): samples n = 0 … N − 1 at t_n = n·T_s cover the program, the
/// filters' settling and the last laser window, then the tail:
/// \f[ N = \lceil (t_{end} + t_{tail}) / T_s \rceil + 1,\quad
///     t_{end} = \max(D_{program} + 2 D,\ \text{last laser-off} + \text{shift}) \f]
/// (a ratio within 1e-9 of an integer counts as that integer).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>

#include "scanhead/nc/nc_program.hpp"
#include "scanhead/nc/nc_stats.hpp"

namespace scanhead
{
struct NcPlan
{
  std::string job_name;
  NcProgram program;                ///< timeline X_inter follows, laser gate on it, builder counts
  double period_s = 0.0;            ///< sample period T_s [s]
  std::uint64_t total_samples = 0;  ///< N above
  double speed_cap_mps = 0.0;       ///< cap applied to every polyline (infinity: none) [m/s]
  double filter_delay_s = 0.0;      ///< delay D of Q_filt2 behind the command: (T1+T2)/2 or the adaptive D [s]
  double gate_shift_s = 0.0;        ///< D − (T1+T2)/2: the laser gate follows the filters by it [s]
  double longest_t1_s = 0.0;        ///< adaptive: T1 of the fastest knot (fixed: T1) [s]
  double longest_t2_s = 0.0;        ///< adaptive: T2 of the fastest knot (fixed: T2) [s]
  Eigen::Vector2d start_joints_rad = Eigen::Vector2d::Zero();  ///< IGT of the start point (rest) [rad]
  /// \brief Low-frequency delay of the servo behind its setpoint, the larger of the two axes [s]
  /// (GalvoServo::lowFrequencyDelay); NaN when the NC was given no servo model.
  double servo_delay_s = 0.0;

  /// \brief How far the actual path lags the ideal timeline: filter + servo delay [s].
  double actualDelay() const { return filter_delay_s + servo_delay_s; }
  /// \brief Duration of the program (Σ L/v + holds + skywriting) [s].
  double pathDuration() const { return program.timeline.duration(); }
};

/// \brief The plan's figures as NcStats, for reports; the per-sample figures (maxima, counts) are
/// zero: the NC accumulates them while it samples.
inline NcStats ncStatsOf(const NcPlan& plan)
{
  NcStats stats;
  stats.program = plan.program.stats;
  stats.speed_cap_mps = plan.speed_cap_mps;
  stats.filter_delay_s = plan.filter_delay_s;
  stats.gate_shift_s = plan.gate_shift_s;
  stats.longest_t1_s = plan.longest_t1_s;
  stats.longest_t2_s = plan.longest_t2_s;
  return stats;
}
}  // namespace scanhead
