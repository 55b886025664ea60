#include "bag_source_ros.hpp"
#include "ros_node_main.hpp"

int main(int argc, char** argv)
{
  return scanhead::runNode<scanhead::BagSourceNode>(argc, argv, "bag_source");
}
