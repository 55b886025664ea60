/// \file galvo_servo_ros.hpp
/// \brief The servo node: nc/setpoint in; galvo/joint_states_chunk (full rate) and
/// /joint_states (decimated to ~display_rate_hz of wall time, for robot_state_publisher) out.
#pragma once

#include <ros/ros.h>
#include <scanhead/JointStreamChunk.h>
#include <scanhead/NcSetpoint.h>

#include <memory>

#include "ros_chunk_outlet.hpp"
#include "ros_stage_node.hpp"
#include "scanhead/chain/chain_stages.hpp"

namespace scanhead
{
class GalvoServoNode
{
public:
  /// Parameters: ~consumers (node names, default optical_chain), ~display_rate_hz (default 30),
  /// ~stall_timeout_s (ros_stage_node.hpp).
  GalvoServoNode(ros::NodeHandle& nh, ros::NodeHandle& private_nh);
  bool failed() const { return false; }

private:
  GalvoServoNode(ros::NodeHandle& nh, ros::NodeHandle& private_nh, const ChainConfig& config);
  void onTimer(const ros::TimerEvent&);
  void publishDisplay(const JointSample& sample);

  double period_s_;  ///< nc.period_s: a stream at another period is warned about
  ServoStage stage_;
  ChunkOutlet<JointStreamChunk> joints_out_;
  std::unique_ptr<StageNodeAdapter<ServoStage, NcSetpoint>> adapter_;
  ros::Publisher display_pub_;
  ros::Timer timer_;
  double display_period_s_ = 1.0 / 30.0;
  ros::WallTime last_display_;
  JointSample last_display_sample_;  ///< at rest at 0 before the first job
};
}  // namespace scanhead
