/// \file cam_path_publisher_ros.hpp
/// \brief Publishes a scan job (file or built-in) on cam/job, latched; more via cam/load.
#pragma once

#include <ros/ros.h>
#include <std_msgs/String.h>

#include "scanhead/chain/chain_config.hpp"

namespace scanhead
{
class CamPathPublisherNode
{
public:
  /// Parameters: ~job (file or built-in spec, default "corner"), ~exit_on_error (default false).
  CamPathPublisherNode(ros::NodeHandle& nh, ros::NodeHandle& private_nh);
  /// \brief True when the start-up job failed with ~exit_on_error set (the node then shuts down).
  bool failed() const { return failed_; }

private:
  /// \return false if the job could not be loaded (error logged)
  bool publishJob(const std::string& job_argument);
  void onLoad(const std_msgs::String& msg);

  ChainConfig config_;
  ros::Publisher job_pub_;
  ros::Subscriber load_sub_;
  std::uint32_t next_job_id_ = 1;
  bool exit_on_error_ = false;
  bool failed_ = false;
};
}  // namespace scanhead
