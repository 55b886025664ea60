#include "optical_chain_ros.hpp"

#include "ros_config.hpp"
#include "ros_conversions.hpp"

namespace scanhead
{
namespace
{
/// Chunks of older jobs left incomplete this long are dropped (and reported): bounds memory.
constexpr std::size_t kMaxPendingChunks = 4096;
}

OpticalChainNode::OpticalChainNode(ros::NodeHandle& nh, ros::NodeHandle& private_nh)
  : spot_out_(nh, "optics/spot", expectedSubscribers(nh, private_nh, "subscribers", 1))
{
  const ChainConfig config = chainConfigFromParams(nh);
  optics_ = opticalModelFromParams(nh, config.optics);
  stage_ = std::make_unique<OpticalChainStage>(*optics_);
  const auto hints = ros::TransportHints().tcpNoDelay();
  setpoint_sub_ = nh.subscribe("nc/setpoint", 0, &OpticalChainNode::onSetpoint, this, hints);
  laser_sub_ = nh.subscribe("nc/laser", 0, &OpticalChainNode::onLaser, this, hints);
  joints_sub_ = nh.subscribe("galvo/joint_states_chunk", 0, &OpticalChainNode::onJoints, this, hints);
  timer_ = nh.createTimer(ros::Duration(0.01), &OpticalChainNode::onTimer, this);
}

void OpticalChainNode::onSetpoint(const NcSetpoint::ConstPtr& msg)
{
  const Key key{msg->chunk.job_id, msg->chunk.first_index};
  pending_[key].setpoint = std::make_unique<NcSetpoint>(*msg);
  tryProcess(key);
}

void OpticalChainNode::onLaser(const NcLaser::ConstPtr& msg)
{
  const Key key{msg->chunk.job_id, msg->chunk.first_index};
  pending_[key].laser = std::make_unique<NcLaser>(*msg);
  tryProcess(key);
}

void OpticalChainNode::onJoints(const JointStreamChunk::ConstPtr& msg)
{
  const Key key{msg->chunk.job_id, msg->chunk.first_index};
  pending_[key].joints = std::make_unique<JointStreamChunk>(*msg);
  tryProcess(key);
}

void OpticalChainNode::tryProcess(const Key& key)
{
  const auto it = pending_.find(key);
  Pending& p = it->second;
  if (p.setpoint && p.laser && p.joints)
  {
    try
    {
      const SpotChunk spots = stage_->process(fromMsg(*p.setpoint), fromMsg(*p.joints), fromMsg(*p.laser));
      spot_out_.push(toMsg(spots, p.setpoint->chunk));
    }
    catch (const std::exception& e)
    {
      ROS_ERROR("optics: job %u chunk at sample %llu dropped: %s", key.first,
                static_cast<unsigned long long>(key.second), e.what());
    }
    pending_.erase(it);
  }
  while (pending_.size() > kMaxPendingChunks)
  {
    ROS_ERROR("optics: job %u chunk at sample %llu never completed (a stream lost it); dropped",
              pending_.begin()->first.first, static_cast<unsigned long long>(pending_.begin()->first.second));
    pending_.erase(pending_.begin());
  }
}

void OpticalChainNode::onTimer(const ros::TimerEvent&)
{
  spot_out_.flush();
}
}  // namespace scanhead
