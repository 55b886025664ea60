#include "nc_interpolator_ros.hpp"
#include "ros_node_main.hpp"

int main(int argc, char** argv)
{
  return scanhead::runNode<scanhead::NcInterpolatorNode>(argc, argv, "nc_interpolator");
}
