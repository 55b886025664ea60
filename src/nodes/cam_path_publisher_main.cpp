#include "cam_path_publisher_ros.hpp"
#include "ros_node_main.hpp"

int main(int argc, char** argv)
{
  return scanhead::runNode<scanhead::CamPathPublisherNode>(argc, argv, "cam_path_publisher");
}
