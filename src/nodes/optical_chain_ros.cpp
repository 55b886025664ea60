#include "optical_chain_ros.hpp"

#include "ros_config.hpp"
#include "ros_conversions.hpp"

namespace scanhead
{
OpticalChainNode::OpticalChainNode(ros::NodeHandle& nh, ros::NodeHandle& private_nh)
  : spot_out_(nh, private_nh, "optics/spot", "consumers", {"energy_accumulator"})
{
  const ChainConfig config = chainConfigFromParams(nh);
  optics_ = opticalModelFromParams(nh, config.optics);
  stage_ = std::make_unique<OpticsStage>(*optics_);
  beam_view_ = std::make_unique<BeamView>(nh, *optics_);
  Adapter::Binding binding;
  // The optics needs nothing of the job: its reset argument is empty (the plan is not read).
  binding.job = [](const ChunkInfo&) { return std::optional<NoInput>(NoInput()); };
  binding.process = [this](OpticsStage& stage, const Adapter::Messages& m) {
    const SetpointChunk setpoint = fromMsg(*std::get<0>(m));
    const LaserChunk laser = fromMsg(*std::get<1>(m));
    const JointChunk joints = fromMsg(*std::get<2>(m));
    SpotChunk spots = stage.process({setpoint, joints, laser});
    beam_view_->record(joints, spots);
    return spots;
  };
  binding.publish = [this](const SpotChunk& spots, const ChunkHeader& header) { spot_out_.push(toMsg(spots, header)); };
  adapter_ = std::make_unique<Adapter>(
      nh, private_nh, *stage_, std::array<std::string, 3>{"nc/setpoint", "nc/laser", "galvo/joint_states_chunk"},
      std::move(binding), "optics");
  timer_ = nh.createTimer(ros::Duration(0.01), [this](const ros::TimerEvent&) { spot_out_.refresh(); });
}
}  // namespace scanhead
