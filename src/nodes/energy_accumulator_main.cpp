#include "energy_accumulator_ros.hpp"
#include "ros_node_main.hpp"

int main(int argc, char** argv)
{
  return scanhead::runNode<scanhead::EnergyAccumulatorNode>(argc, argv, "energy_accumulator");
}
