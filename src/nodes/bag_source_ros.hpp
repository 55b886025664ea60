/// \file bag_source_ros.hpp
/// \brief Replays the NC's output from a recorded bag (cam/job, nc/setpoint, nc/laser) into
/// the downstream stages, with the same flow control as the live NC, so nothing is dropped.
#pragma once

#include <ros/ros.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <scanhead/ChunkAck.h>
#include <scanhead/NcJobPlan.h>
#include <scanhead/NcLaser.h>
#include <scanhead/NcSetpoint.h>
#include <scanhead/ScanJob.h>

#include <memory>

#include "ros_chunk_outlet.hpp"
#include "ros_flow_window.hpp"
#include "ros_liveness.hpp"

namespace scanhead
{
class BagSourceNode
{
public:
  /// Parameters: ~bag (path, required), ~window_chunks (default 16), ~setpoint_consumers (node
  /// names, default galvo_servo optical_chain), ~laser_consumers (optical_chain), ~ready_timeout_s
  /// (20), ~flow_timeout_s (10): past either the replay ends with an error naming what is missing,
  /// except that a full window whose consumers are all alive (pinged: ros_liveness.hpp) waits
  /// until ~hang_timeout_s (default the global hang_timeout_s, else 60; 0: never).
  BagSourceNode(ros::NodeHandle& nh, ros::NodeHandle& private_nh);
  bool failed() const { return failed_; }

private:
  void onAck(const ChunkAck& msg);
  void onTimer(const ros::TimerEvent&);
  /// \brief Publishes recorded chunks while the in-flight window allows.
  void pump();

  rosbag::Bag bag_;
  std::unique_ptr<rosbag::View> view_;
  rosbag::View::iterator next_;
  ros::Publisher job_pub_, plan_pub_;
  ChunkOutlet<NcSetpoint> setpoint_out_;
  ChunkOutlet<NcLaser> laser_out_;
  ros::Subscriber ack_sub_;
  ros::Timer timer_;
  std::uint64_t window_samples_ = 16000;
  FlowWindow window_;
  double ready_timeout_s_ = 20.0, flow_timeout_s_ = 10.0;
  ros::WallTime flow_clock_;  ///< since when the window has waited for an acknowledgement
  double hang_timeout_s_ = 60.0;
  UpstreamWatch downstream_;  ///< the stages owing acknowledgements (upstream of energy/ack)
  ros::WallTime last_ping_;   ///< the last liveness check of a full window
  bool flow_warned_ = false;  ///< the full window's wait on live stages was reported
  bool failed_ = false;
};
}  // namespace scanhead
