#include "energy_accumulator_ros.hpp"

#include <signal.h>

#include <cstdio>

#include <scanhead/ChunkAck.h>
#include <scanhead/JobMetrics.h>

#include "ros_config.hpp"
#include "ros_conversions.hpp"
#include "ros_energy_views.hpp"
#include "ros_launch_end.hpp"
#include "scanhead/chain/config_io.hpp"
#include "scanhead/chain/results_writer.hpp"
#include "scanhead/chain/run_plan.hpp"
#include "scanhead/common/errors.hpp"
#include "scanhead/metrics/metrics_report.hpp"
#include "support/python_plots.hpp"

namespace scanhead
{
EnergyAccumulatorNode::EnergyAccumulatorNode(ros::NodeHandle& nh, ros::NodeHandle& private_nh)
  : config_(chainConfigFromParams(nh))
  , settings_yaml_(chainConfigToYaml(config_))
  , optics_(opticalModelFromParams(nh, config_.optics))
  , stage_(config_)
  , nh_(nh)
{
  std::string base_dir;
  private_nh.param("out", out_, std::string());
  private_nh.param("base_dir", base_dir, std::string());
  private_nh.param("exit_when_done", exit_when_done_, false);
  private_nh.param("shutdown_delay_s", shutdown_delay_s_, 0.0);
  private_nh.param("start_timeout_s", start_timeout_s_, start_timeout_s_);
  if (!out_.empty() && out_.front() != '/' && !base_dir.empty())
    out_ = base_dir + "/" + out_;
  // Latched: an NC that connects late still learns how far the stream got (no deadlock).
  ack_pub_ = nh.advertise<ChunkAck>("energy/ack", 100, true);
  metrics_pub_ = nh.advertise<JobMetrics>("energy/metrics", 1, true);
  // The views are rendered only for subscribers (rendering costs more than a short job): now if
  // someone listens, else when someone connects, from the last finished job.
  image_pub_ = nh.advertise<sensor_msgs::Image>(
      "energy/map", 1, [this](const ros::SingleSubscriberPublisher&) { publishViews(); }, {}, {}, true);
  grid_pub_ = nh.advertise<nav_msgs::OccupancyGrid>(
      "energy/map_grid", 1, [this](const ros::SingleSubscriberPublisher&) { publishViews(); }, {}, {}, true);
  markers_pub_ = nh.advertise<visualization_msgs::MarkerArray>(
      "energy/path_markers", 1, [this](const ros::SingleSubscriberPublisher&) { publishViews(); }, {}, {}, true);
  job_sub_ = nh.subscribe("cam/job", 10, &EnergyAccumulatorNode::onJob, this);
  plan_sub_ = nh.subscribe("nc/plan", 10, &EnergyAccumulatorNode::onPlan, this);
  StageNodeAdapter<EnergySinkStage, SpotStream>::Binding binding;
  // A job starts once its cam/job and the NC's plan of it are both here (its chunks wait till then).
  binding.job = [this](const ChunkInfo& chunk) -> std::optional<PlannedJob> {
    if (rejected_plans_.count(chunk.job_id) != 0)
      throw InputError("its nc/plan was rejected (see above)");
    const auto job = jobs_.find(chunk.job_id);
    const auto plan = plans_.find(chunk.job_id);
    if (job == jobs_.end() || plan == plans_.end())
      return std::nullopt;
    current_job_ = job->second;  // kept for the results: jobs_ forgets old jobs
    return PlannedJob{current_job_, plan->second};
  };
  binding.process = [](EnergySinkStage& stage, const std::tuple<std::shared_ptr<const SpotStream>>& m) {
    return stage.process(fromMsg(*std::get<0>(m)));  // the stage counts gaps and overlaps (dropped_samples)
  };
  // Every chunk is acknowledged, even one the stage threw on: the NC's flow window never waits for it.
  binding.consumed = [this](const ChunkInfo& chunk) { acknowledge(chunk.total_samples); };
  binding.finished = [this](std::uint32_t job_id, bool ok) { finishJob(job_id, ok); };
  binding.stalled = [this](const StreamStall& stall) { finishStalledJob(stall); };
  binding.unstartable = [this](std::uint32_t job_id) {
    ROS_ERROR("energy: job %u: no results (its cam/job or nc/plan never came)", job_id);
    failed_ = true;
    shutdownIfDone();
  };
  start_timer_ = nh.createWallTimer(ros::WallDuration(0.5), [this](const ros::WallTimerEvent&) { checkStarts(); });
  adapter_ = std::make_unique<StageNodeAdapter<EnergySinkStage, SpotStream>>(
      nh, private_nh, stage_, std::array<std::string, 1>{"optics/spot"}, std::move(binding), "energy");
}

void EnergyAccumulatorNode::onJob(const ScanJob& msg)
{
  jobs_[msg.job_id] = fromMsg(msg);
  while (jobs_.size() > 8)
    jobs_.erase(jobs_.begin());
  adapter_->retry();
}

void EnergyAccumulatorNode::onPlan(const NcJobPlan& msg)
{
  try
  {
    plans_[msg.job_id] = fromMsg(msg);
    rejected_plans_.erase(msg.job_id);
    if (start_timeout_s_ > 0.0 && adapter_->driver().jobId() != msg.job_id)
      planned_at_[msg.job_id] = ros::WallTime::now();
    while (plans_.size() > 8)
      plans_.erase(plans_.begin());
  }
  catch (const std::exception& e)
  {
    ROS_ERROR("energy: nc/plan of job %u rejected: %s", msg.job_id, e.what());
    plans_.erase(msg.job_id);
    rejected_plans_.insert(msg.job_id);
  }
  // The plan carries the NC's timing, so corners stay on time whatever this node's settings; but a
  // graph whose stages are configured differently is a mistake worth saying.
  try
  {
    const std::vector<std::string> differ =
        differingSettings(msg.settings_yaml, settings_yaml_, {"stream", "nc", "recipe", "servo", "optics"});
    if (!differ.empty())
    {
      std::string text;
      for (const std::string& line : differ)
        text += "\n  " + line;
      ROS_ERROR(
          "energy: configured differently from the NC node (NC's value vs this node's):%s\n"
          "The NC's plan is used; give every node the same config (and set:=) to compare runs.",
          text.c_str());
    }
  }
  catch (const std::exception& e)
  {
    ROS_WARN("energy: cannot compare the NC node's settings with this node's: %s", e.what());
  }
  adapter_->retry();
}

void EnergyAccumulatorNode::checkStarts()
{
  for (auto it = planned_at_.begin(); it != planned_at_.end();)
  {
    const std::uint32_t job_id = it->first;
    const double waited = (ros::WallTime::now() - it->second).toSec();
    if (adapter_->driver().jobId() == job_id)
      it = planned_at_.erase(it);  // its first chunk came
    else if (waited > start_timeout_s_)
    {
      // The NC planned the job but no chunk of it ever came here: the NC gave it up (a consumer
      // missing, see its log) or a stage before this one is not there.
      ROS_ERROR(
          "energy: job %u: no results: its nc/plan came %.1f s ago (~start_timeout_s) but none of its "
          "optics/spot chunks (is every stage running? see the NC's log)",
          job_id, waited);
      it = planned_at_.erase(it);
      failed_ = true;
      shutdownIfDone();
    }
    else
      ++it;
  }
}

void EnergyAccumulatorNode::acknowledge(std::uint64_t total_samples)
{
  const std::uint32_t job_id = adapter_->driver().jobId();
  const std::uint64_t next_index = adapter_->driver().sequence().next();
  ChunkAck ack;
  ack.job_id = job_id;
  ack.next_index = next_index;
  ack_pub_.publish(ack);
  if (total_samples > 100000)  // progress on jobs longer than a second of machine time
    ROS_INFO_THROTTLE(2.0, "energy: job %u at %.0f %% (%llu of %llu samples)", job_id,
                      100.0 * static_cast<double>(next_index) / static_cast<double>(total_samples),
                      static_cast<unsigned long long>(next_index), static_cast<unsigned long long>(total_samples));
}

void EnergyAccumulatorNode::finishStalledJob(const StreamStall& stall)
{
  if (adapter_->driver().failed())
  {
    finishJob(stall.job_id, false);
    return;
  }
  // What arrived is accumulated: the results are written as they are, marked incomplete, with the
  // samples that never came counted as dropped and where the stream stopped.
  RunMetrics metrics = stage_.finish();
  metrics.dropped_samples += stall.total_samples - std::min(stall.total_samples, stall.next_sample);
  metrics.complete = false;
  metrics.stream_gap = StreamGap{stall.streams, stall.next_sample, stall.total_samples, stall.waited_s};
  ROS_ERROR(
      "energy: job %u is INCOMPLETE: its stream stopped at sample %llu of %llu (%s); writing what arrived, "
      "marked complete: false",
      stall.job_id, static_cast<unsigned long long>(stall.next_sample),
      static_cast<unsigned long long>(stall.total_samples), stall.streams.c_str());
  failed_ = true;
  finishResults(stall.job_id, metrics);
}

void EnergyAccumulatorNode::finishJob(std::uint32_t job_id, bool ok)
{
  if (adapter_->driver().failed())
  {
    ROS_ERROR("energy: job %u could not run: no results", job_id);
    failed_ = true;
    shutdownIfDone();
    return;
  }
  if (!ok)
  {
    ROS_ERROR("energy: job %u: a chunk failed (see above): its results are incomplete", job_id);
    failed_ = true;
  }
  finishResults(job_id, stage_.finish());
}

void EnergyAccumulatorNode::finishResults(std::uint32_t job_id, RunMetrics metrics)
{
  // The run plan's warnings, as the batch runner records them (graph = batch, byte for byte).
  try
  {
    metrics.warnings = planRun(config_, current_job_, *optics_).warnings;
  }
  catch (const std::exception& e)
  {
    ROS_WARN("energy: job %u: no run-plan warnings (%s)", job_id, e.what());
  }
  ROS_INFO_STREAM("energy: job " << job_id << " done\n" << metricsTable(metrics));
  publishResults(job_id, metrics);
  if (!out_.empty())
  {
    try
    {
      writeResultsFolder(out_, metrics, stage_.stage(), config_, current_job_, plotFinisher());
      ROS_INFO("energy: results written to %s/", out_.c_str());
    }
    catch (const std::exception& e)
    {
      ROS_ERROR("energy: cannot write the results folder: %s", e.what());
      failed_ = true;
    }
  }
  last_stage_ = stage_.release();
  last_job_ = current_job_;
  views_published_ = false;
  publishViews();
  shutdownIfDone();
}

void EnergyAccumulatorNode::shutdownIfDone()
{
  if (exit_when_done_ && failed_)
    ROS_FATAL("energy: the job failed (see above); shutting down with an error (exit code 1)");
  if (exit_when_done_)  // after a delay that lets a recorder write the last chunks
    shutdown_timer_ = nh_.createWallTimer(
        ros::WallDuration(std::max(shutdown_delay_s_, 1e-3)),
        [this](const ros::WallTimerEvent&) {
          // Done: under roslaunch, end the whole launch as Ctrl-C does (exit 0, no "REQUIRED process has died"
          // banner); a failure, rostest or a node started by hand end this process (the required-node path).
          const pid_t launcher = failed_ ? -1 : roslaunchAncestor();
          if (launcher > 0)
          {
            ROS_INFO("scanhead: done, results in %s", out_.empty() ? "(no results folder)" : out_.c_str());
            // Out now: a nodelet manager's stdout is a block-buffered pipe to roslaunch, which may kill it before
            // it exits normally (the line would be lost on a loaded machine).
            std::fflush(nullptr);
            if (::kill(launcher, SIGINT) == 0)
              return;
          }
          ros::shutdown();
        },
        true);
}

void EnergyAccumulatorNode::publishResults(std::uint32_t job_id, const RunMetrics& metrics)
{
  JobMetrics msg;
  msg.header.stamp = ros::Time::now();
  msg.job_id = job_id;
  msg.job_name = metrics.job_name;
  msg.samples = metrics.samples;
  msg.dropped_samples = metrics.dropped_samples;
  msg.duration_s = metrics.duration_s;
  msg.laser_on_time_s = metrics.laser_on_time_s;
  msg.commanded_energy_j = metrics.commanded_energy_j;
  msg.deposited_energy_j = metrics.deposited_energy_j;
  msg.metrics_yaml = metricsToYaml(metrics);
  metrics_pub_.publish(msg);
}

void EnergyAccumulatorNode::publishViews()
{
  const bool wanted =
      image_pub_.getNumSubscribers() + grid_pub_.getNumSubscribers() + markers_pub_.getNumSubscribers() > 0;
  if (!last_stage_ || views_published_ || !wanted)
    return;
  // A bounded overview of the sparse map (block means), whatever the job's extent.
  const TiledEnergyMap& map = last_stage_->map();
  const EnergyMap overview = map.overview(map.overviewFactor(2000));
  image_pub_.publish(energyImage(overview));
  grid_pub_.publish(energyGrid(overview));
  markers_pub_.publish(pathMarkers(last_job_, last_stage_->trace()));
  views_published_ = true;  // latched from now on: later subscribers get them without a new render
}
}  // namespace scanhead
