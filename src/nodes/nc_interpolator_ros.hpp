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
#include "ros_liveness.hpp"
#include "scanhead/chain/chain_config.hpp"
#include "scanhead/chain/chain_stages.hpp"

namespace scanhead
{
class NcInterpolatorNode
{
public:
  /// Parameters: ~setpoint_consumers (node names, default galvo_servo optical_chain),
  /// ~laser_consumers (optical_chain), ~debug_consumers (none): the consumers each stream waits
  /// for (plus the global stream_recorders); ~ready_timeout_s (default 20): how long a job's chunks
  /// wait for a missing consumer; ~flow_timeout_s (default 10): how long the full window waits for
  /// an acknowledgement before the nodes downstream are pinged (ros_liveness.hpp): if one owing
  /// acknowledgements is gone the job is abandoned naming it; if all are alive (a slow stage) a
  /// warning is logged and the window waits until ~hang_timeout_s (default the global
  /// hang_timeout_s, else 60; 0: never). Each timeout abandons the job with an error naming what
  /// is missing. ~exit_on_error (default false; the launch sets it with out:=): a rejected job
  /// shuts the node down with an error, which ends a one-job launch.
  NcInterpolatorNode(ros::NodeHandle& nh, ros::NodeHandle& private_nh);
  /// \brief True when a job failed with ~exit_on_error set (the node then shuts down).
  bool failed() const { return failed_; }

private:
  void onJob(const ScanJob& msg);
  void onAck(const ChunkAck& msg);
  void onTimer(const ros::TimerEvent&);
  /// \brief Publishes chunks while the in-flight window allows.
  void pump();
  /// \brief Gives the current job up (logged with \p why): its held chunks are dropped.
  void abandon(const std::string& why);

  ChainConfig config_;
  std::unique_ptr<OpticalModel> optics_;
  std::unique_ptr<NcStage> nc_;  ///< the current job's NC (none after an abandoned job)
  /// The previous job's NC, started again for the next job: its IGT tables depend on the config alone (~2.7 ms a job
  /// to build again); a job that fails to start leaves the current one running.
  std::unique_ptr<NcStage> spare_nc_;
  ChunkOutlet<NcSetpoint> setpoint_out_;
  ChunkOutlet<NcLaser> laser_out_;
  ChunkOutlet<NcDebug> debug_out_;
  ros::Subscriber job_sub_, ack_sub_;
  ros::Publisher plan_pub_;    ///< nc/plan, latched: the plan of the current job
  std::string settings_yaml_;  ///< this node's settings, sent with each plan
  ros::Timer timer_;
  FlowWindow window_;
  bool exit_on_error_ = false;
  bool failed_ = false;
  double ready_timeout_s_ = 20.0, flow_timeout_s_ = 10.0, hang_timeout_s_ = 60.0;
  ros::WallTime flow_clock_;  ///< since when the window has waited for an acknowledgement
  UpstreamWatch downstream_;  ///< the stages owing acknowledgements (upstream of energy/ack)
  ros::WallTime last_ping_;   ///< the last liveness check of a full window
  bool flow_warned_ = false;  ///< the full window's wait on live stages was reported
};
}  // namespace scanhead
