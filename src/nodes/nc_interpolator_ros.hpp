/// \file nc_interpolator_ros.hpp
/// \brief The NC node: cam/job in; nc/setpoint, nc/laser (and nc/debug) chunks out, paced by
/// the acknowledgements of the last stage (at most stream.window_chunks chunks in flight).
#pragma once

#include <ros/ros.h>
#include <scanhead/ChunkAck.h>
#include <scanhead/NcDebug.h>
#include <scanhead/NcLaser.h>
#include <scanhead/NcSetpoint.h>
#include <scanhead/ScanJob.h>

#include <memory>

#include "ros_chunk_outlet.hpp"
#include "ros_flow_window.hpp"
#include "scanhead/chain/chain_config.hpp"
#include "scanhead/chain/chain_stages.hpp"

namespace scanhead
{
class NcInterpolatorNode
{
public:
  /// Parameters: ~setpoint_subscribers (default 2: servo and optics), ~laser_subscribers (1).
  NcInterpolatorNode(ros::NodeHandle& nh, ros::NodeHandle& private_nh);
  bool failed() const { return false; }

private:
  void onJob(const ScanJob& msg);
  void onAck(const ChunkAck& msg);
  void onTimer(const ros::TimerEvent&);
  /// \brief Publishes chunks while the in-flight window allows.
  void pump();

  ChainConfig config_;
  std::unique_ptr<OpticalModel> optics_;
  std::unique_ptr<NcStage> nc_;  ///< the current job's NC (a new one per job: a rejected job leaves none)
  ChunkOutlet<NcSetpoint> setpoint_out_;
  ChunkOutlet<NcLaser> laser_out_;
  ChunkOutlet<NcDebug> debug_out_;
  ros::Subscriber job_sub_, ack_sub_;
  ros::Publisher plan_pub_;    ///< nc/plan, latched: the plan of the current job
  std::string settings_yaml_;  ///< this node's settings, sent with each plan
  ros::Timer timer_;
  FlowWindow window_;
};
}  // namespace scanhead
