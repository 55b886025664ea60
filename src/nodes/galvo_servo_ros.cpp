#include "galvo_servo_ros.hpp"

#include <sensor_msgs/JointState.h>

#include "ros_config.hpp"
#include "ros_conversions.hpp"

namespace scanhead
{
GalvoServoNode::GalvoServoNode(ros::NodeHandle& nh, ros::NodeHandle& private_nh)
  : joints_out_(nh, "galvo/joint_states_chunk", expectedSubscribers(nh, private_nh, "subscribers", 1))
{
  const ChainConfig config = chainConfigFromParams(nh);
  period_s_ = config.nc.period_s;
  servo_config_ = config.servo;
  servo_ = std::make_unique<GalvoServo>(servo_config_, period_s_);
  double rate_hz = 30.0;
  private_nh.param("display_rate_hz", rate_hz, rate_hz);
  display_period_s_ = 1.0 / std::max(rate_hz, 1e-3);
  display_pub_ = nh.advertise<sensor_msgs::JointState>("joint_states", 10);
  setpoint_sub_ = nh.subscribe("nc/setpoint", 0, &GalvoServoNode::onSetpoint, this,
                               ros::TransportHints().tcpNoDelay());
  timer_ = nh.createTimer(ros::Duration(0.01), &GalvoServoNode::onTimer, this);
}

void GalvoServoNode::onSetpoint(const NcSetpoint& msg)
{
  try
  {
    const SetpointChunk setpoint = fromMsg(msg);
    if (msg.chunk.job_id != job_id_ || msg.chunk.first_index == 0)
    {
      if (msg.chunk.first_index != 0 || setpoint.samples.empty())
      {
        ROS_ERROR("galvo: job %u starts at sample %llu, not 0: chunks lost; waiting for a job start",
                  msg.chunk.job_id, static_cast<unsigned long long>(msg.chunk.first_index));
        return;
      }
      if (msg.chunk.period != period_s_)
        ROS_WARN("galvo: stream period %g s differs from nc.period_s %g s; using the stream's", msg.chunk.period,
                 period_s_);
      period_s_ = msg.chunk.period;
      servo_ = std::make_unique<GalvoServo>(servo_config_, period_s_);
      servo_->reset(setpoint.samples.front().position);
      job_id_ = msg.chunk.job_id;
      sequence_.reset();
    }
    const std::uint64_t expected = sequence_.next();
    sequence_.admit(msg.chunk.first_index, setpoint.samples.size());
    if (msg.chunk.first_index != expected)
      ROS_ERROR("galvo: job %u: expected sample %llu, got %llu (gap or reordering upstream)", job_id_,
                static_cast<unsigned long long>(expected), static_cast<unsigned long long>(msg.chunk.first_index));
    const JointChunk joints = servo_->process(setpoint);
    joints_out_.push(toMsg(joints, msg.chunk));
    const bool last = joints.endIndex() >= msg.chunk.total_samples;
    if (!joints.samples.empty() && (last || (ros::WallTime::now() - last_display_).toSec() >= display_period_s_))
      publishDisplay(joints.samples.back());
  }
  catch (const std::exception& e)
  {
    ROS_ERROR("galvo: bad setpoint chunk: %s", e.what());
  }
}

void GalvoServoNode::publishDisplay(const JointSample& sample)
{
  sensor_msgs::JointState state;
  state.header.stamp = ros::Time::now();
  state.name = {kJointNames[0], kJointNames[1]};
  state.position = {sample.position.x(), sample.position.y()};
  state.velocity = {sample.velocity.x(), sample.velocity.y()};
  state.effort = {sample.current.x(), sample.current.y()};
  display_pub_.publish(state);
  last_display_ = ros::WallTime::now();
  last_display_sample_ = sample;
}

void GalvoServoNode::onTimer(const ros::TimerEvent&)
{
  joints_out_.flush();
  // Keep the TF of the mirrors fresh between jobs (robot_state_publisher needs joint states).
  if ((ros::WallTime::now() - last_display_).toSec() >= display_period_s_)
    publishDisplay(last_display_sample_);
}
}  // namespace scanhead
