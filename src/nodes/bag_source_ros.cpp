#include "bag_source_ros.hpp"

#include "scanhead/common/errors.hpp"

namespace scanhead
{
BagSourceNode::BagSourceNode(ros::NodeHandle& nh, ros::NodeHandle& private_nh)
  : setpoint_out_(nh, private_nh, "nc/setpoint", "setpoint_consumers", {"galvo_servo", "optical_chain"})
  , laser_out_(nh, private_nh, "nc/laser", "laser_consumers", {"optical_chain"})
  , downstream_(nh)
{
  hang_timeout_s_ = timeoutParam(nh, private_nh, "hang_timeout_s", hang_timeout_s_);
  private_nh.param("ready_timeout_s", ready_timeout_s_, ready_timeout_s_);
  private_nh.param("flow_timeout_s", flow_timeout_s_, flow_timeout_s_);
  std::string path;
  if (!private_nh.getParam("bag", path) || path.empty())
    throw ConfigError("~bag: the bag to replay is not set (bag:=FILE)");
  int window_chunks = 16, chunk_samples = 1000;
  private_nh.param("window_chunks", window_chunks, window_chunks);
  nh.param("config/stream/chunk_samples", chunk_samples, chunk_samples);
  window_samples_ = static_cast<std::uint64_t>(std::max(1, window_chunks)) * std::max(1, chunk_samples);
  window_.start(0, window_samples_);  // until the bag's first job
  bag_.open(path, rosbag::bagmode::Read);
  // rosbag record stores the names as given on its command line: relative or resolved.
  std::vector<std::string> topics;
  for (const char* name : {"cam/job", "nc/plan", "nc/setpoint", "nc/laser"})
  {
    topics.push_back(name);
    topics.push_back(nh.resolveName(name));
  }
  view_ = std::make_unique<rosbag::View>(bag_, rosbag::TopicQuery(topics));
  if (view_->size() == 0)
    throw InputError(path + ": no cam/job, nc/setpoint or nc/laser messages to replay");
  // The energy stage takes each job's timing from the NC's plan: a bag without it cannot be replayed.
  rosbag::View plans(bag_, rosbag::TopicQuery(std::vector<std::string>{"nc/plan", nh.resolveName("nc/plan")}));
  if (plans.size() == 0)
    throw InputError(path +
                     ": no nc/plan messages (recorded by a scanhead older than the NC plan message): "
                     "record it again with virtual_machine.launch record:=true");
  next_ = view_->begin();
  job_pub_ = nh.advertise<ScanJob>("cam/job", 1, true);
  plan_pub_ = nh.advertise<NcJobPlan>("nc/plan", 1, true);
  ack_sub_ = nh.subscribe("energy/ack", 100, &BagSourceNode::onAck, this, ros::TransportHints().tcpNoDelay());
  timer_ = nh.createTimer(ros::Duration(0.01), &BagSourceNode::onTimer, this);
  ROS_INFO("bag_source: replaying %u messages from %s", view_->size(), path.c_str());
}

void BagSourceNode::onAck(const ChunkAck& msg)
{
  if (window_.onAck(msg))
  {
    flow_clock_ = ros::WallTime::now();
    flow_warned_ = false;
    pump();
  }
}

void BagSourceNode::onTimer(const ros::TimerEvent&)
{
  if (failed_)
    return;
  setpoint_out_.refresh();
  laser_out_.refresh();
  pump();
  // A replay is one run: a consumer that never comes or a stream that stops ends it with an error.
  std::string error;
  if (setpoint_out_.waitedS() > ready_timeout_s_)
    error = setpoint_out_.missingText();
  else if (laser_out_.waitedS() > ready_timeout_s_)
    error = laser_out_.missingText();
  else if (setpoint_out_.pending() + laser_out_.pending() > 0 || next_ == view_->end() || window_.canSend())
    flow_clock_ = ros::WallTime::now();
  else if ((ros::WallTime::now() - flow_clock_).toSec() > flow_timeout_s_ &&
           (ros::WallTime::now() - last_ping_).toSec() >= 1.0)
  {
    // A full window is an error only if a stage owing acknowledgements is gone, or hangs too long.
    last_ping_ = ros::WallTime::now();
    const double waited = (last_ping_ - flow_clock_).toSec();
    const UpstreamLiveness live = downstream_.check({ack_sub_.getTopic()}, 0.5);
    const std::string where =
        "no energy/ack for " + std::to_string(waited) + " s at sample " + std::to_string(window_.acked());
    if (live.anyDead())
      error = where + " (~flow_timeout_s); gone: " + UpstreamLiveness::join(live.dead);
    else if (hang_timeout_s_ > 0.0 && waited > hang_timeout_s_)
      error = where + " (~hang_timeout_s); alive: " + UpstreamLiveness::join(live.alive) +
              (live.unanswered.empty() ? "" : "; not answering: " + UpstreamLiveness::join(live.unanswered));
    else if (!flow_warned_)
    {
      ROS_WARN("bag_source: %s; %s alive: a slow stage holds the flow", where.c_str(),
               UpstreamLiveness::join(live.alive).c_str());
      flow_warned_ = true;
    }
  }
  if (error.empty())
    return;
  ROS_FATAL("bag_source: replay abandoned: %s", error.c_str());
  failed_ = true;
  ros::shutdown();
}

void BagSourceNode::pump()
{
  while (next_ != view_->end() && window_.canSend())
  {
    const rosbag::MessageInstance& m = *next_;
    if (const auto job = m.instantiate<ScanJob>())
    {
      window_.start(job->job_id, window_samples_);
      flow_clock_ = ros::WallTime::now();
      job_pub_.publish(job);
    }
    else if (const auto plan = m.instantiate<NcJobPlan>())
      plan_pub_.publish(plan);
    else if (const auto setpoint = m.instantiate<NcSetpoint>())
    {
      setpoint_out_.push(setpoint);
      window_.sent(setpoint->chunk.first_index + setpoint->trajectory.points.size());
    }
    else if (const auto laser = m.instantiate<NcLaser>())
      laser_out_.push(laser);
    ++next_;
  }
}
}  // namespace scanhead
