#include "graph_benchmark_ros.hpp"
#include "ros_node_main.hpp"

int main(int argc, char** argv)
{
  return scanhead::runNode<scanhead::GraphBenchmarkNode>(argc, argv, "graph_benchmark");
}
