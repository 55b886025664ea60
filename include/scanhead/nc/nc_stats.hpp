/// \file nc_stats.hpp
/// \brief What the NC did to a job, as plain figures for reports: the program builder's changes
/// and the sampled setpoint against the joint limits.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>

namespace scanhead
{
/// \brief Counts of what the builder changed, for reports.
struct NcProgramStats
{
  std::size_t capped_polylines = 0;    ///< polylines slowed to speed_cap_mps
  std::size_t delay_holds = 0;         ///< mark + jump delay holds inserted
  std::size_t polygon_holds = 0;       ///< polygon delay holds inserted
  std::size_t skywritten_corners = 0;  ///< corners replaced by run-out, turn, run-in
  double added_time_s = 0.0;           ///< program duration − Σ L/v of the recipe's job after the speed cap [s]
};

/// \brief What the NC did to a job, for reports (accumulated over the samples produced so far).
struct NcStats
{
  NcProgramStats program;
  double speed_cap_mps = 0.0;   ///< cap applied to every polyline (infinity: none) [m/s]
  double filter_delay_s = 0.0;  ///< delay of Q_filt2 behind the command: (T1+T2)/2 or D [s]
  double gate_shift_s = 0.0;    ///< filter_delay_s − (T1+T2)/2: the laser gate follows it [s]
  double longest_t1_s = 0.0;    ///< adaptive: T1 of the fastest knot (fixed: T1) [s]
  double longest_t2_s = 0.0;    ///< adaptive: T2 of the fastest knot (fixed: T2) [s]
  Eigen::Vector2d max_accel_radps2 = Eigen::Vector2d::Zero();  ///< max |q̈| of Q_filt2 per axis
  Eigen::Vector2d max_jerk_radps3 = Eigen::Vector2d::Zero();   ///< max |Δq̈/Ts| of Q_filt2 per axis
  std::uint64_t samples_over_accel = 0;                        ///< samples with |q̈_i| > A (1e-6 relative slack)
  std::uint64_t samples_over_jerk = 0;                         ///< samples with |Δq̈_i/Ts| > J (1e-6 relative slack)
  std::uint64_t laser_on_samples = 0;
};
}  // namespace scanhead
