#include "graph_benchmark_ros.hpp"

#include <std_msgs/String.h>

#include <algorithm>

namespace scanhead
{
GraphBenchmarkNode::GraphBenchmarkNode(ros::NodeHandle& nh, ros::NodeHandle& private_nh)
{
  private_nh.param("job", job_, std::string("corner"));
  private_nh.param("repeat", repeat_, 10);
  load_pub_ = nh.advertise<std_msgs::String>("cam/load", 10);
  metrics_sub_ = nh.subscribe("energy/metrics", 10, &GraphBenchmarkNode::onMetrics, this);
}

void GraphBenchmarkNode::onMetrics(const JobMetrics& msg)
{
  if (msg.job_id <= last_job_id_)
    return;
  last_job_id_ = msg.job_id;
  if (started_ > 0)  // the launch's own first job is the warm-up
  {
    wall_s_.push_back((ros::WallTime::now() - request_time_).toSec());
    job_s_.push_back(msg.duration_s);
    dropped_.push_back(msg.dropped_samples);
  }
  if (started_ < repeat_)
    requestNext();
  else
  {
    report();
    ros::shutdown();
  }
}

void GraphBenchmarkNode::requestNext()
{
  while (load_pub_.getNumSubscribers() == 0 && ros::ok())
    ros::WallDuration(0.01).sleep();
  std_msgs::String msg;
  msg.data = job_;
  request_time_ = ros::WallTime::now();
  load_pub_.publish(msg);
  ++started_;
}

void GraphBenchmarkNode::report() const
{
  std::vector<double> rtf;
  for (std::size_t i = 0; i < wall_s_.size(); ++i)
    rtf.push_back(job_s_[i] / wall_s_[i]);
  std::sort(rtf.begin(), rtf.end());
  double mean = 0;
  for (double r : rtf)
    mean += r / rtf.size();
  unsigned long long dropped = 0;
  for (auto d : dropped_)
    dropped += d;
  std::printf(
      "graph benchmark, job %s: %zu runs of %.2f ms machine time; real-time factor mean %.1fx, "
      "worst %.1fx, best %.1fx; dropped samples %llu\n",
      job_.c_str(), rtf.size(), job_s_.empty() ? 0.0 : job_s_[0] * 1e3, mean, rtf.front(), rtf.back(), dropped);
  std::fflush(stdout);
}
}  // namespace scanhead
