#include "galvo_servo_ros.hpp"

#include <sensor_msgs/JointState.h>

#include "ros_config.hpp"
#include "ros_conversions.hpp"

namespace scanhead
{
GalvoServoNode::GalvoServoNode(ros::NodeHandle& nh, ros::NodeHandle& private_nh)
  : GalvoServoNode(nh, private_nh, chainConfigFromParams(nh))
{
}

GalvoServoNode::GalvoServoNode(ros::NodeHandle& nh, ros::NodeHandle& private_nh, const ChainConfig& config)
  : period_s_(config.nc.period_s)
  , stage_(config.servo)
  , joints_out_(nh, private_nh, "galvo/joint_states_chunk", "consumers", {"optical_chain"})
{
  double rate_hz = 30.0;
  private_nh.param("display_rate_hz", rate_hz, rate_hz);
  display_period_s_ = 1.0 / std::max(rate_hz, 1e-3);
  display_pub_ = nh.advertise<sensor_msgs::JointState>("joint_states", 10);
  StageNodeAdapter<ServoStage, NcSetpoint>::Binding binding;
  binding.job = [this](const ChunkInfo& chunk) -> std::optional<ServoJob> {
    if (chunk.period_s != period_s_)
      ROS_WARN("galvo: stream period %g s differs from nc.period_s %g s; using the stream's", chunk.period_s,
               period_s_);
    return ServoJob{chunk.period_s};
  };
  binding.process = [](ServoStage& stage, const std::tuple<std::shared_ptr<const NcSetpoint>>& m) {
    return stage.process(fromMsg(*std::get<0>(m)));
  };
  binding.publish = [this](const JointChunk& joints, const ChunkHeader& header) {
    joints_out_.push(toMsg(joints, header));
    const bool last = joints.endIndex() >= header.total_samples;
    if (!joints.samples.empty() && (last || (ros::WallTime::now() - last_display_).toSec() >= display_period_s_))
      publishDisplay(joints.samples.back());
  };
  adapter_ = std::make_unique<StageNodeAdapter<ServoStage, NcSetpoint>>(
      nh, private_nh, stage_, std::array<std::string, 1>{"nc/setpoint"}, std::move(binding), "galvo");
  timer_ = nh.createTimer(ros::Duration(0.01), &GalvoServoNode::onTimer, this);
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
  joints_out_.refresh();
  // Keep the TF of the mirrors fresh between jobs (robot_state_publisher needs joint states).
  if ((ros::WallTime::now() - last_display_).toSec() >= display_period_s_)
    publishDisplay(last_display_sample_);
}
}  // namespace scanhead
