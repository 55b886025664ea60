#include "nc_interpolator_ros.hpp"

#include <boost/make_shared.hpp>
#include <cstdio>

#include "scanhead/chain/config_io.hpp"
#include "scanhead/chain/run_plan.hpp"
#include "scanhead/metrics/metrics_report.hpp"

#include "ros_config.hpp"
#include "ros_conversions.hpp"
#include "scanhead/job/formats/job_io.hpp"

namespace scanhead
{
namespace
{
std::string seconds(double s)
{
  char text[32];
  std::snprintf(text, sizeof(text), "%.1f s", s);
  return text;
}
}  // namespace

NcInterpolatorNode::NcInterpolatorNode(ros::NodeHandle& nh, ros::NodeHandle& private_nh)
  : config_(chainConfigFromParams(nh))
  , optics_(opticalModelFromParams(nh, config_.optics))
  , setpoint_out_(nh, private_nh, "nc/setpoint", "setpoint_consumers", {"galvo_servo", "optical_chain"})
  , laser_out_(nh, private_nh, "nc/laser", "laser_consumers", {"optical_chain"})
  , debug_out_(nh, private_nh, "nc/debug", "debug_consumers", {})
  , downstream_(nh)
{
  private_nh.param("exit_on_error", exit_on_error_, false);
  private_nh.param("ready_timeout_s", ready_timeout_s_, ready_timeout_s_);
  private_nh.param("flow_timeout_s", flow_timeout_s_, flow_timeout_s_);
  hang_timeout_s_ = timeoutParam(nh, private_nh, "hang_timeout_s", hang_timeout_s_);
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
    // As in the batch runner: a job beyond limits.* (machine time, samples, memory) is refused here.
    const RunPlan run_plan = planRun(config_, job, *optics_);
    enforceRunLimits(run_plan, config_.limits, physicalMemoryBytes());
    ROS_INFO("nc: job %u %s", msg.job_id, runPlanText(run_plan).c_str());
    for (const std::string& warning : run_plan.warnings)
      ROS_WARN("nc: job %u: warning: %s", msg.job_id, warning.c_str());
    std::unique_ptr<NcStage> nc = spare_nc_ ? std::move(spare_nc_) : std::make_unique<NcStage>(config_, *optics_);
    try
    {
      nc->reset(job);
    }
    catch (...)
    {
      spare_nc_ = std::move(nc);  // (started again by the next job)
      throw;
    }
    spare_nc_ = std::move(nc_);
    nc_ = std::move(nc);
    // Before any chunk of the job; shared, so a nodelet energy stage gets it without a copy.
    plan_pub_.publish(boost::make_shared<const NcJobPlan>(toMsg(nc_->plan(), msg.job_id, settings_yaml_)));
    window_.start(msg.job_id, config_.stream.window_chunks * config_.stream.chunk_samples);
    setpoint_out_.clear();  // what an abandoned job left
    laser_out_.clear();
    debug_out_.clear();
    flow_clock_ = ros::WallTime::now();
    flow_warned_ = false;
    ROS_INFO("nc: job %u '%s': %llu samples (%.3f ms)", msg.job_id, job.name.c_str(),
             static_cast<unsigned long long>(nc_->plan().total_samples),
             1e3 * nc_->plan().total_samples * config_.nc.period_s);
    pump();
  }
  catch (const std::exception& e)
  {
    ROS_ERROR("nc: job %u '%s' rejected: %s", msg.job_id, msg.name.c_str(), e.what());
    if (exit_on_error_)
    {
      ROS_FATAL("nc: shutting down with an error (exit code 1): the job of this launch was rejected");
      failed_ = true;
      ros::shutdown();
    }
  }
}

void NcInterpolatorNode::onAck(const ChunkAck& msg)
{
  if (window_.onAck(msg))
  {
    flow_clock_ = ros::WallTime::now();
    if (flow_warned_)
      ROS_INFO("nc: job %u resumed: energy/ack at sample %llu", window_.jobId(),
               static_cast<unsigned long long>(window_.acked()));
    flow_warned_ = false;
    pump();
  }
}

void NcInterpolatorNode::onTimer(const ros::TimerEvent&)
{
  setpoint_out_.refresh();
  laser_out_.refresh();
  debug_out_.refresh();
  if (!nc_)
    return;
  // Held for a consumer that is not there: the handshake's timeout.
  std::string missing;
  const auto check = [&](const auto& outlet) {
    if (missing.empty() && outlet.waitedS() > ready_timeout_s_)
      missing = "its chunks waited " + seconds(outlet.waitedS()) +
                " (~ready_timeout_s) for a consumer: " + outlet.missingText();
  };
  check(setpoint_out_);
  check(laser_out_);
  check(debug_out_);
  if (!missing.empty())
  {
    abandon(missing);
    return;
  }
  const bool held = setpoint_out_.pending() + laser_out_.pending() + debug_out_.pending() > 0;
  if (held || nc_->done() || window_.canSend())
  {
    flow_clock_ = ros::WallTime::now();  // not waiting for an acknowledgement
    return;
  }
  const ros::WallTime now = ros::WallTime::now();
  const double waited = (now - flow_clock_).toSec();
  if (waited <= flow_timeout_s_ || (now - last_ping_).toSec() < 1.0)
    return;
  // A full window is an error only if a stage owing acknowledgements is gone, or hangs too long:
  // the energy node may just be busy (a big job's results). Checked at most once a second.
  last_ping_ = now;
  const UpstreamLiveness live = downstream_.check({ack_sub_.getTopic()}, 0.5);
  const std::string where = "no energy/ack for " + seconds(waited) + " with the window full at sample " +
                            std::to_string(window_.acked()) + " of " + std::to_string(nc_->plan().total_samples);
  if (live.anyDead())
    abandon(where + " (~flow_timeout_s " + seconds(flow_timeout_s_) + "); gone: " + UpstreamLiveness::join(live.dead));
  else if (hang_timeout_s_ > 0.0 && waited > hang_timeout_s_)
    abandon(where + " (~hang_timeout_s " + seconds(hang_timeout_s_) +
            "); alive: " + UpstreamLiveness::join(live.alive) +
            (live.unanswered.empty() ? "" : "; not answering: " + UpstreamLiveness::join(live.unanswered)));
  else if (!flow_warned_)
  {
    ROS_WARN("nc: job %u: %s; %s alive%s: a slow stage holds the flow (abandoned after ~hang_timeout_s %.1f s)",
             window_.jobId(), where.c_str(), UpstreamLiveness::join(live.alive).c_str(),
             live.unanswered.empty()
                 ? ""
                 : ("; " + UpstreamLiveness::join(live.unanswered) + " not answering (stopped or busy)").c_str(),
             hang_timeout_s_);
    flow_warned_ = true;
  }
}

void NcInterpolatorNode::abandon(const std::string& why)
{
  ROS_ERROR("nc: job %u abandoned: %s", window_.jobId(), why.c_str());
  spare_nc_ = std::move(nc_);
  setpoint_out_.clear();
  laser_out_.clear();
  debug_out_.clear();
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
