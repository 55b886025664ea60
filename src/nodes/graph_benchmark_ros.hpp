/// \file graph_benchmark_ros.hpp
/// \brief Measures the node graph's real-time factor: loads a job N times through cam/load and
/// times each from the request to its energy/metrics (job time / wall time). Not a stage.
#pragma once

#include <ros/ros.h>
#include <scanhead/JobMetrics.h>

#include <vector>

namespace scanhead
{
class GraphBenchmarkNode
{
public:
  /// Parameters: ~job (default "corner"), ~repeat (default 10).
  GraphBenchmarkNode(ros::NodeHandle& nh, ros::NodeHandle& private_nh);
  bool failed() const { return false; }

private:
  void onMetrics(const JobMetrics& msg);
  void requestNext();
  void report() const;

  ros::Publisher load_pub_;
  ros::Subscriber metrics_sub_;
  std::string job_;
  int repeat_ = 10;
  int started_ = 0;
  std::uint32_t last_job_id_ = 0;
  ros::WallTime request_time_;
  std::vector<double> wall_s_, job_s_;
  std::vector<unsigned long long> dropped_;
};
}  // namespace scanhead
