/// \file chunk.hpp
/// \brief Full-rate streams travel in chunks of samples: first global sample index + period.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

namespace scanhead
{
/// \brief A run of consecutive samples of one stream; sample k is at time (first_index + k)·period_s.
template <class Sample>
struct Chunk
{
  std::uint64_t first_index = 0;  ///< global index of samples[0]
  double period_s = 1e-5;         ///< sample period Ts [s]
  std::vector<Sample> samples;

  std::uint64_t endIndex() const { return first_index + samples.size(); }
};

/// \brief NC output per sample: Q_filt2 and its derivatives, the position setpoint of the servos.
struct SetpointSample
{
  Eigen::Vector2d position = Eigen::Vector2d::Zero();      ///< [rad] mechanical, (galvo_x, galvo_y)
  Eigen::Vector2d velocity = Eigen::Vector2d::Zero();      ///< [rad/s]
  Eigen::Vector2d acceleration = Eigen::Vector2d::Zero();  ///< [rad/s^2]
};

/// \brief Laser command per sample, aligned with the setpoint stream.
struct LaserSample
{
  double power_w = 0.0;  ///< [W]
};

/// \brief Intermediate NC signals for analysis (nc/debug, SPEC §1; NC Fig. 2).
struct NcDebugSample
{
  Eigen::Vector2d x_inter = Eigen::Vector2d::Zero();               ///< sampled CAM path [m]
  Eigen::Vector2d q_inter = Eigen::Vector2d::Zero();               ///< after the inverse geometric transform [rad]
  Eigen::Vector2d q_inter_velocity = Eigen::Vector2d::Zero();      ///< backward difference [rad/s]
  Eigen::Vector2d q_inter_acceleration = Eigen::Vector2d::Zero();  ///< second backward difference [rad/s²]
  Eigen::Vector2d q_filt1 = Eigen::Vector2d::Zero();               ///< after FIR T1 [rad]
  Eigen::Vector2d q_filt1_velocity = Eigen::Vector2d::Zero();      ///< [rad/s]
  Eigen::Vector2d q_filt1_acceleration = Eigen::Vector2d::Zero();  ///< [rad/s²]
};

/// \brief Measured joint state per sample (servo output).
struct JointSample
{
  Eigen::Vector2d position = Eigen::Vector2d::Zero();  ///< [rad]
  Eigen::Vector2d velocity = Eigen::Vector2d::Zero();  ///< [rad/s]
  Eigen::Vector2d current = Eigen::Vector2d::Zero();   ///< motor current [A] (effort)
};

/// \brief Spot on the work plane per sample.
struct SpotSample
{
  Eigen::Vector2d setpoint = Eigen::Vector2d::Zero();     ///< Q_filt2 through the direct model [m]
  Eigen::Vector2d actual = Eigen::Vector2d::Zero();       ///< Q_exp through the direct model [m]
  Eigen::Vector3d direction = Eigen::Vector3d(0, 0, -1);  ///< unit beam direction at the plane (plane frame)
  Eigen::Vector2d angle_error = Eigen::Vector2d::Zero();  ///< Q_filt2 − Q_exp per axis [rad] (servo following error)
  double power_w = 0.0;                                   ///< laser power [W]
};

using SetpointChunk = Chunk<SetpointSample>;
using LaserChunk = Chunk<LaserSample>;
using NcDebugChunk = Chunk<NcDebugSample>;
using JointChunk = Chunk<JointSample>;
using SpotChunk = Chunk<SpotSample>;
}  // namespace scanhead
