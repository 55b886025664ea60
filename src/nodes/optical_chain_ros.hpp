/// \file optical_chain_ros.hpp
/// \brief The optics node: joins nc/setpoint, nc/laser and galvo/joint_states_chunk by sample
/// index and publishes optics/spot.
#pragma once

#include <ros/ros.h>
#include <scanhead/JointStreamChunk.h>
#include <scanhead/NcLaser.h>
#include <scanhead/NcSetpoint.h>
#include <scanhead/SpotStream.h>

#include <map>
#include <memory>

#include "ros_chunk_outlet.hpp"
#include "scanhead/optics/optical_chain_stage.hpp"

namespace scanhead
{
class OpticalChainNode
{
public:
  /// Parameters: ~subscribers (default 1: energy).
  OpticalChainNode(ros::NodeHandle& nh, ros::NodeHandle& private_nh);
  bool failed() const { return false; }

private:
  /// The three inputs of one chunk, as they arrive.
  struct Pending
  {
    std::unique_ptr<NcSetpoint> setpoint;
    std::unique_ptr<NcLaser> laser;
    std::unique_ptr<JointStreamChunk> joints;
  };
  using Key = std::pair<std::uint32_t, std::uint64_t>;  ///< (job id, first index)

  void onSetpoint(const NcSetpoint::ConstPtr& msg);
  void onLaser(const NcLaser::ConstPtr& msg);
  void onJoints(const JointStreamChunk::ConstPtr& msg);
  void onTimer(const ros::TimerEvent&);
  /// \brief Processes the chunk at \p key once its three parts are there.
  void tryProcess(const Key& key);

  std::unique_ptr<OpticalModel> optics_;
  std::unique_ptr<OpticalChainStage> stage_;
  ChunkOutlet<SpotStream> spot_out_;
  ros::Subscriber setpoint_sub_, laser_sub_, joints_sub_;
  ros::Timer timer_;
  std::map<Key, Pending> pending_;
};
}  // namespace scanhead
