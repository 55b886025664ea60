#include "galvo_servo_ros.hpp"
#include "ros_node_main.hpp"

int main(int argc, char** argv)
{
  return scanhead::runNode<scanhead::GalvoServoNode>(argc, argv, "galvo_servo");
}
