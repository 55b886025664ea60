/// \file ros_node_main.hpp
/// \brief The shared main of every stage node: init, construct from (nh, ~), spin.
#pragma once

#include <ros/ros.h>

namespace scanhead
{
/// \return 1 if the node could not start (the error is logged), else 0
template <class Node>
int runNode(int argc, char** argv, const char* name)
{
  ros::init(argc, argv, name);
  ros::NodeHandle nh, private_nh("~");
  try
  {
    Node node(nh, private_nh);
    ros::spin();
    return node.failed() ? 1 : 0;
  }
  catch (const std::exception& e)
  {
    ROS_FATAL("%s: %s", name, e.what());
    return 1;
  }
}
}  // namespace scanhead
