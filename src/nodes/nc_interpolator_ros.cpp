#include "nc_interpolator_ros.hpp"

#include <boost/make_shared.hpp>

#include "scanhead/chain/config_io.hpp"
#include "scanhead/metrics/metrics_report.hpp"

#include "ros_config.hpp"
#include "ros_conversions.hpp"
#include "scanhead/job/formats/job_io.hpp"

namespace scanhead
{
NcInterpolatorNode::NcInterpolatorNode(ros::NodeHandle& nh, ros::NodeHandle& private_nh)
  : config_(chainConfigFromParams(nh))
  , optics_(opticalModelFromParams(nh, config_.optics))
  , setpoint_out_(nh, "nc/setpoint", expectedSubscribers(nh, private_nh, "setpoint_subscribers", 2))
  , laser_out_(nh, "nc/laser", expectedSubscribers(nh, private_nh, "laser_subscribers", 1))
  , debug_out_(nh, "nc/debug", expectedSubscribers(nh, private_nh, "debug_subscribers", 0))
{
  settings_yaml_ = chainConfigToYaml(config_);
  plan_pub_ = nh.advertise<NcJobPlan>("nc/plan", 1, true);
  job_sub_ = nh.subscribe("cam/job", 10, &NcInterpolatorNode::onJob, this);
  ack_sub_ = nh.subscribe("energy/ack", 100, &NcInterpolatorNode::onAck, this, ros::TransportHints().tcpNoDelay());
  timer_ = nh.createTimer(ros::Duration(0.01), &NcInterpolatorNode::onTimer, this);
}

void NcInterpolatorNode::onJob(const ScanJob& msg)
{
  try
  {
    const Job job = fromMsg(msg);
    validateScanJob(job, config_.optics.field_half_width_m);
    auto nc = std::make_unique<NcStage>(config_, *optics_);
    nc->reset(job);
    nc_ = std::move(nc);
    // Before any chunk of the job; shared, so a nodelet energy stage gets it without a copy.
    plan_pub_.publish(boost::make_shared<const NcJobPlan>(toMsg(nc_->plan(), msg.job_id, settings_yaml_)));
    window_.start(msg.job_id, config_.stream.window_chunks * config_.stream.chunk_samples);
    ROS_INFO("nc: job %u '%s': %llu samples (%.3f ms)", msg.job_id, job.name.c_str(),
             static_cast<unsigned long long>(nc_->plan().total_samples),
             1e3 * nc_->plan().total_samples * config_.nc.period_s);
    pump();
  }
  catch (const std::exception& e)
  {
    ROS_ERROR("nc: job %u '%s' rejected: %s", msg.job_id, msg.name.c_str(), e.what());
  }
}

void NcInterpolatorNode::onAck(const ChunkAck& msg)
{
  if (window_.onAck(msg))
    pump();
}

void NcInterpolatorNode::onTimer(const ros::TimerEvent&)
{
  setpoint_out_.flush();
  laser_out_.flush();
  debug_out_.flush();
}

void NcInterpolatorNode::pump()
{
  if (!nc_)
    return;
  while (!nc_->done() && window_.canSend())
  {
    const NcOutput out = nc_->process(config_.stream.chunk_samples);
    const ChunkHeader header =
        makeChunkHeader(window_.jobId(), out.setpoint.first_index, out.setpoint.period_s, nc_->plan().total_samples);
    setpoint_out_.push(toMsg(out.setpoint, header));
    laser_out_.push(toMsg(out.laser, header));
    if (config_.nc.debug)
      debug_out_.push(toMsg(out.debug, header));
    window_.sent(out.setpoint.endIndex());
    if (nc_->done())
      ROS_INFO("nc: job %u done; %s", window_.jobId(), ncLimitsLine(nc_->interpolator().stats(), config_.nc).c_str());
  }
}
}  // namespace scanhead
