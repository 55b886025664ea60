#include "optical_chain_ros.hpp"
#include "ros_node_main.hpp"

int main(int argc, char** argv)
{
  return scanhead::runNode<scanhead::OpticalChainNode>(argc, argv, "optical_chain");
}
