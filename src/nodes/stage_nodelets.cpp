/// \file stage_nodelets.cpp
/// \brief The stages as nodelets (nodelet_plugins.xml): one manager runs the whole graph in one
/// process with zero-copy transport; each stage's *_main.cpp still runs it as its own node.
#include <pluginlib/class_list_macros.hpp>

#include "bag_source_ros.hpp"
#include "cam_path_publisher_ros.hpp"
#include "energy_accumulator_ros.hpp"
#include "galvo_servo_ros.hpp"
#include "nc_interpolator_ros.hpp"
#include "optical_chain_ros.hpp"
#include "ros_stage_nodelet.hpp"

namespace scanhead
{
// Named classes (not aliases): the plugin's type names in nodelet_plugins.xml.
class CamPathPublisherNodelet : public StageNodelet<CamPathPublisherNode>
{
};
class NcInterpolatorNodelet : public StageNodelet<NcInterpolatorNode>
{
};
class GalvoServoNodelet : public StageNodelet<GalvoServoNode>
{
};
class OpticalChainNodelet : public StageNodelet<OpticalChainNode>
{
};
class EnergyAccumulatorNodelet : public StageNodelet<EnergyAccumulatorNode>
{
};
class BagSourceNodelet : public StageNodelet<BagSourceNode>
{
};
}  // namespace scanhead

PLUGINLIB_EXPORT_CLASS(scanhead::CamPathPublisherNodelet, nodelet::Nodelet)
PLUGINLIB_EXPORT_CLASS(scanhead::NcInterpolatorNodelet, nodelet::Nodelet)
PLUGINLIB_EXPORT_CLASS(scanhead::GalvoServoNodelet, nodelet::Nodelet)
PLUGINLIB_EXPORT_CLASS(scanhead::OpticalChainNodelet, nodelet::Nodelet)
PLUGINLIB_EXPORT_CLASS(scanhead::EnergyAccumulatorNodelet, nodelet::Nodelet)
PLUGINLIB_EXPORT_CLASS(scanhead::BagSourceNodelet, nodelet::Nodelet)
