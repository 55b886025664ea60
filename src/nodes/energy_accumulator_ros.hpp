/// \file energy_accumulator_ros.hpp
/// \brief The energy node: cam/job, nc/plan (the NC's plan of each job) and optics/spot in; energy/ack (flow control),
/// energy/metrics, energy/map (image), energy/map_grid (on the work plane in rviz), energy/path_markers out; writes the
/// results folder when ~out is set.
#pragma once

#include <ros/ros.h>
#include <scanhead/NcJobPlan.h>
#include <scanhead/ScanJob.h>
#include <scanhead/SpotStream.h>

#include <map>
#include <memory>
#include <set>

#include "ros_stage_node.hpp"
#include "scanhead/chain/chain_config.hpp"
#include "scanhead/chain/chain_stages.hpp"
#include "scanhead/chain/energy_sink_stage.hpp"
#include "scanhead/chain/energy_stage.hpp"
#include "scanhead/optics/optical_model.hpp"

namespace scanhead
{
class EnergyAccumulatorNode
{
public:
  /// Parameters: ~out (results folder, default none), ~base_dir (resolves a relative ~out),
  /// ~exit_when_done (default false: shut down after the first job, for batch-like launches; with
  /// exit code 1 if it failed or stalled), ~stall_timeout_s (ros_stage_node.hpp), ~start_timeout_s
  /// (default 30: a job planned by the NC none of whose chunks came by then fails).
  EnergyAccumulatorNode(ros::NodeHandle& nh, ros::NodeHandle& private_nh);
  bool failed() const { return failed_; }

private:
  void onJob(const ScanJob& msg);
  void onPlan(const NcJobPlan& msg);
  /// \brief A planned job none of whose chunks came within ~start_timeout_s fails (no results).
  void checkStarts();
  /// \brief Acknowledges the spot stream up to where it got, with progress on long jobs.
  void acknowledge(std::uint64_t total_samples);
  /// \brief The job's last sample is in: metrics, results folder, views (\p ok: no chunk failed).
  void finishJob(std::uint32_t job_id, bool ok);
  /// \brief The stream stopped mid-job: what arrived is written as an incomplete result.
  void finishStalledJob(const StreamStall& stall);
  /// \brief Publishes and writes \p metrics (with the run plan's warnings, as the batch runner's) and
  /// the stage's map, renders the views, ends if asked.
  void finishResults(std::uint32_t job_id, RunMetrics metrics);
  /// \brief With ~exit_when_done, shuts the node down after a delay that lets a recorder finish.
  void shutdownIfDone();
  void publishResults(std::uint32_t job_id, const RunMetrics& metrics);
  /// \brief Energy image, grid and path markers of the last finished job, if anyone subscribes.
  void publishViews();

  ChainConfig config_;
  std::string settings_yaml_;               ///< this node's settings, compared with the NC's
  std::unique_ptr<OpticalModel> optics_;    ///< for the run plan's warnings (as the batch runner's)
  std::map<std::uint32_t, Job> jobs_;       ///< recent jobs by id
  std::map<std::uint32_t, NcPlan> plans_;   ///< the NC's plans of recent jobs, by id
  std::set<std::uint32_t> rejected_plans_;  ///< jobs whose nc/plan could not be read: they fail
  Job current_job_;                         ///< the job running (or last run)
  EnergySinkStage stage_;
  std::unique_ptr<StageNodeAdapter<EnergySinkStage, SpotStream>> adapter_;  ///< optics/spot in
  std::unique_ptr<EnergyStage> last_stage_;                                 ///< the last finished job, for the views
  Job last_job_;
  bool views_published_ = false;
  std::string out_;
  bool exit_when_done_ = false;
  double shutdown_delay_s_ = 0.0;
  double start_timeout_s_ = 30.0;                      ///< > the NC's ready_timeout_s (20 s)
  std::map<std::uint32_t, ros::WallTime> planned_at_;  ///< planned jobs whose first chunk has not come
  ros::WallTimer start_timer_;
  ros::NodeHandle nh_;
  ros::WallTimer shutdown_timer_;
  bool failed_ = false;
  ros::Subscriber job_sub_, plan_sub_;
  ros::Publisher ack_pub_, metrics_pub_, image_pub_, grid_pub_, markers_pub_;
};
}  // namespace scanhead
