#include "energy_accumulator_ros.hpp"

#include <scanhead/ChunkAck.h>
#include <scanhead/JobMetrics.h>

#include "ros_config.hpp"
#include "ros_energy_views.hpp"
#include "ros_conversions.hpp"
#include "scanhead/chain/config_io.hpp"
#include "scanhead/metrics/metrics_report.hpp"
#include "scanhead/chain/results_writer.hpp"
#include "support/python_plots.hpp"

namespace scanhead
{
namespace
{
constexpr std::size_t kMaxWaitingChunks = 4096;
}  // namespace

EnergyAccumulatorNode::EnergyAccumulatorNode(ros::NodeHandle& nh, ros::NodeHandle& private_nh)
  : config_(chainConfigFromParams(nh)), settings_yaml_(chainConfigToYaml(config_)), nh_(nh)
{
  std::string base_dir;
  private_nh.param("out", out_, std::string());
  private_nh.param("base_dir", base_dir, std::string());
  private_nh.param("exit_when_done", exit_when_done_, false);
  private_nh.param("shutdown_delay_s", shutdown_delay_s_, 0.0);
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
  spot_sub_ = nh.subscribe("optics/spot", 0, &EnergyAccumulatorNode::onSpot, this, ros::TransportHints().tcpNoDelay());
}

void EnergyAccumulatorNode::onJob(const ScanJob& msg)
{
  jobs_[msg.job_id] = fromMsg(msg);
  while (jobs_.size() > 8)
    jobs_.erase(jobs_.begin());
  retryWaiting();
}

void EnergyAccumulatorNode::onPlan(const NcJobPlan& msg)
{
  try
  {
    plans_[msg.job_id] = fromMsg(msg);
    while (plans_.size() > 8)
      plans_.erase(plans_.begin());
    // The plan carries the NC's timing, so corners stay on time whatever this node's settings;
    // but a graph whose stages are configured differently is a mistake worth saying.
    const std::vector<std::string> differ =
        differingSettings(msg.settings_yaml, settings_yaml_, {"stream", "nc", "recipe", "servo", "optics"});
    if (!differ.empty())
    {
      std::string text;
      for (const std::string& line : differ)
        text += "\n  " + line;
      ROS_ERROR("energy: configured differently from the NC node (NC's value vs this node's):%s\n"
                "The NC's plan is used; give every node the same config (and set:=) to compare runs.",
                text.c_str());
    }
  }
  catch (const std::exception& e)
  {
    ROS_ERROR("energy: nc/plan of job %u rejected: %s", msg.job_id, e.what());
  }
  retryWaiting();
}

void EnergyAccumulatorNode::retryWaiting()
{
  std::deque<SpotStream::ConstPtr> waiting;
  waiting.swap(waiting_);
  for (const auto& chunk : waiting)
    onSpot(chunk);
}

void EnergyAccumulatorNode::onSpot(const SpotStream::ConstPtr& msg)
{
  if (jobs_.count(msg->chunk.job_id) == 0 || plans_.count(msg->chunk.job_id) == 0)
  {
    waiting_.push_back(msg);  // the latched job or plan has not arrived yet
    if (waiting_.size() > kMaxWaitingChunks)
    {
      ROS_ERROR("energy: no cam/job or nc/plan for job %u: chunk at sample %llu dropped", waiting_.front()->chunk.job_id,
                static_cast<unsigned long long>(waiting_.front()->chunk.first_index));
      waiting_.pop_front();
    }
    return;
  }
  try
  {
    process(*msg);
  }
  catch (const std::exception& e)
  {
    ROS_ERROR("energy: job %u chunk at sample %llu: %s", msg->chunk.job_id,
              static_cast<unsigned long long>(msg->chunk.first_index), e.what());
  }
}

void EnergyAccumulatorNode::process(const SpotStream& msg)
{
  if (msg.chunk.job_id != job_id_ || !stage_)
  {
    if (stage_)
      ROS_WARN("energy: job %u interrupted by job %u after %llu samples", job_id_, msg.chunk.job_id,
               static_cast<unsigned long long>(sequence_.next()));
    job_id_ = msg.chunk.job_id;
    total_samples_ = msg.chunk.total_samples;
    // The NC's plan of this job: corner times, laser windows, delays.
    stage_ = std::make_unique<EnergyStage>(config_, jobs_.at(job_id_), plans_.at(job_id_));
    sequence_.reset();
    if (msg.chunk.first_index != 0)
      ROS_ERROR("energy: job %u starts at sample %llu: the first samples were lost upstream (a stage that "
                "connected late?); they are counted as dropped",
                job_id_, static_cast<unsigned long long>(msg.chunk.first_index));
  }
  const SpotChunk chunk = fromMsg(msg);
  stage_->process(chunk);  // the stage counts gaps and overlaps itself (dropped_samples)
  const bool started = sequence_.started();
  const ChunkAdmission admission = sequence_.admit(chunk.first_index, chunk.samples.size());
  if (admission.broken(started) || admission.skip > 0)
    ROS_WARN("energy: job %u: chunk at sample %llu: %llu samples missing before it, %zu already seen "
             "(counted in dropped_samples)", job_id_, static_cast<unsigned long long>(chunk.first_index),
             static_cast<unsigned long long>(admission.missing), admission.skip);
  const std::uint64_t next_index = sequence_.next();
  ChunkAck ack;
  ack.job_id = job_id_;
  ack.next_index = next_index;
  ack_pub_.publish(ack);
  if (total_samples_ > 100000)  // progress on jobs longer than a second of machine time
    ROS_INFO_THROTTLE(2.0, "energy: job %u at %.0f %% (%llu of %llu samples)", job_id_,
                    100.0 * static_cast<double>(next_index) / static_cast<double>(std::max<std::uint64_t>(1, total_samples_)),
                    static_cast<unsigned long long>(next_index), static_cast<unsigned long long>(total_samples_));
  if (next_index >= total_samples_)
    finishJob();
}

void EnergyAccumulatorNode::finishJob()
{
  const RunMetrics metrics = stage_->finish();
  ROS_INFO_STREAM("energy: job " << job_id_ << " done\n" << metricsTable(metrics));
  publishResults(metrics);
  if (!out_.empty())
  {
    try
    {
      writeResultsFolder(out_, metrics, *stage_, config_, jobs_.at(job_id_), plotFinisher());
      ROS_INFO("energy: results written to %s/", out_.c_str());
    }
    catch (const std::exception& e)
    {
      ROS_ERROR("energy: cannot write the results folder: %s", e.what());
      failed_ = true;
    }
  }
  last_stage_ = std::move(stage_);
  last_job_ = jobs_.at(job_id_);
  views_published_ = false;
  publishViews();
  if (exit_when_done_)  // after a delay that lets a recorder write the last chunks
    shutdown_timer_ = nh_.createWallTimer(ros::WallDuration(std::max(shutdown_delay_s_, 1e-3)),
                                          [](const ros::WallTimerEvent&) { ros::shutdown(); }, true);
}

void EnergyAccumulatorNode::publishResults(const RunMetrics& metrics)
{
  JobMetrics msg;
  msg.header.stamp = ros::Time::now();
  msg.job_id = job_id_;
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
  const bool wanted = image_pub_.getNumSubscribers() + grid_pub_.getNumSubscribers() + markers_pub_.getNumSubscribers() > 0;
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
