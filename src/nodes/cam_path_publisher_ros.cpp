#include "cam_path_publisher_ros.hpp"

#include <boost/make_shared.hpp>

#include "ros_config.hpp"
#include "ros_conversions.hpp"
#include "scanhead/chain/chain_stages.hpp"

namespace scanhead
{
CamPathPublisherNode::CamPathPublisherNode(ros::NodeHandle& nh, ros::NodeHandle& private_nh)
  : config_(chainConfigFromParams(nh))
{
  std::string job = "corner";
  private_nh.param("job", job, job);
  private_nh.param("exit_on_error", exit_on_error_, false);
  job_pub_ = nh.advertise<ScanJob>("cam/job", 1, true);
  load_sub_ = nh.subscribe("cam/load", 10, &CamPathPublisherNode::onLoad, this);
  if (!publishJob(job) && exit_on_error_)
  {
    failed_ = true;
    ros::shutdown();
  }
}

bool CamPathPublisherNode::publishJob(const std::string& job_argument)
{
  try
  {
    CamStage cam(config_.cam, config_.optics.field_half_width_m);
    cam.reset(job_argument);
    const Job job = cam.finish();
    const std::uint32_t id = next_job_id_++;
    job_pub_.publish(boost::make_shared<const ScanJob>(toMsg(job, id)));  // shared: no copy to nodelets
    ROS_INFO("cam: job %u '%s' (%zu polylines) from %s", id, job.name.c_str(), job.polylines.size(),
             job.source.c_str());
    return true;
  }
  catch (const std::exception& e)
  {
    ROS_ERROR("cam: cannot load job '%s': %s", job_argument.c_str(), e.what());
    return false;
  }
}

void CamPathPublisherNode::onLoad(const std_msgs::String& msg)
{
  publishJob(msg.data);
}
}  // namespace scanhead
