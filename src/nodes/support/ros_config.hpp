/// \file ros_config.hpp
/// \brief The run configuration and the optical model from the parameter server, through the
/// same core parser as the batch runner (so the graph and the batch runs use identical values).
#pragma once

#include <ros/node_handle.h>

#include <memory>

#include "scanhead/chain/chain_config.hpp"
#include "scanhead/optics/optical_model.hpp"

namespace scanhead
{
/// \brief Reads the `config` tree (config/scanhead.yaml loaded with rosparam) and the
/// `config_overrides` string ("section.key=value ..."), both resolved in \p nh's namespace.
/// \throws ConfigError naming the key
ChainConfig chainConfigFromParams(const ros::NodeHandle& nh);

/// \brief The optical model of the URDF in `robot_description`. \throws InputError
std::unique_ptr<OpticalModel> opticalModelFromParams(const ros::NodeHandle& nh, const OpticsConfig& config);
}  // namespace scanhead
