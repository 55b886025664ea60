/// \file galvo_servo_ros.hpp
/// \brief The servo node: nc/setpoint in; galvo/joint_states_chunk (full rate) and
/// /joint_states (decimated to ~display_rate_hz of wall time, for robot_state_publisher) out.
#pragma once

#include <ros/ros.h>
#include <scanhead/JointStreamChunk.h>
#include <scanhead/NcSetpoint.h>

#include <memory>

#include "ros_chunk_outlet.hpp"
#include "scanhead/common/chunk_sequencer.hpp"
#include "scanhead/servo/galvo_servo.hpp"

namespace scanhead
{
class GalvoServoNode
{
public:
  /// Parameters: ~subscribers (default 1: optics), ~display_rate_hz (default 30).
  GalvoServoNode(ros::NodeHandle& nh, ros::NodeHandle& private_nh);
  bool failed() const { return false; }

private:
  void onSetpoint(const NcSetpoint& msg);
  void onTimer(const ros::TimerEvent&);
  void publishDisplay(const JointSample& sample);

  double period_s_;
  ServoConfig servo_config_;
  std::unique_ptr<GalvoServo> servo_;
  ChunkOutlet<JointStreamChunk> joints_out_;
  ros::Publisher display_pub_;
  ros::Subscriber setpoint_sub_;
  ros::Timer timer_;
  std::uint32_t job_id_ = 0;
  ChunkSequencer sequence_;  ///< gaps and reordering of the setpoint stream
  double display_period_s_ = 1.0 / 30.0;
  ros::WallTime last_display_;
  JointSample last_display_sample_;  ///< at rest at 0 before the first job
};
}  // namespace scanhead
