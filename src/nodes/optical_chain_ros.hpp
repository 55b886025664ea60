/// \file optical_chain_ros.hpp
/// \brief The optics node: joins nc/setpoint, nc/laser and galvo/joint_states_chunk by sample
/// index and publishes optics/spot (and, for rviz, optics/beam: ros_beam_view.hpp).
#pragma once

#include <ros/ros.h>
#include <scanhead/JointStreamChunk.h>
#include <scanhead/NcLaser.h>
#include <scanhead/NcSetpoint.h>
#include <scanhead/SpotStream.h>

#include <memory>

#include "ros_beam_view.hpp"
#include "ros_chunk_outlet.hpp"
#include "ros_stage_node.hpp"
#include "scanhead/chain/chain_stages.hpp"

namespace scanhead
{
class OpticalChainNode
{
public:
  /// Parameters: ~consumers (node names, default energy_accumulator), ~stall_timeout_s (ros_stage_node.hpp).
  OpticalChainNode(ros::NodeHandle& nh, ros::NodeHandle& private_nh);
  bool failed() const { return false; }

private:
  using Adapter = StageNodeAdapter<OpticsStage, NcSetpoint, NcLaser, JointStreamChunk>;

  std::unique_ptr<OpticalModel> optics_;
  std::unique_ptr<OpticsStage> stage_;
  std::unique_ptr<BeamView> beam_view_;
  ChunkOutlet<SpotStream> spot_out_;
  std::unique_ptr<Adapter> adapter_;
  ros::Timer timer_;
};
}  // namespace scanhead
