// The CAM node survives a missing file and a bad built-in spec, the NC survives a job with NaN
// and a point outside the field; then a good job flows through both.
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <scanhead/NcSetpoint.h>
#include <scanhead/ScanJob.h>
#include <std_msgs/String.h>

#include <cmath>

using namespace scanhead;

namespace
{
template <class Predicate>
bool waitFor(Predicate done, double seconds)
{
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(seconds);
  while (!done() && ros::ok() && ros::WallTime::now() < deadline)
  {
    ros::spinOnce();
    ros::WallDuration(0.01).sleep();
  }
  return done();
}

ScanJob badJob(std::uint32_t id, double speed, double x)
{
  ScanJob job;
  job.job_id = id;
  job.name = "bad";
  ScanPolyline line;
  line.type = ScanPolyline::MARK;
  line.speed = speed;
  line.power = 100.0;
  line.x = {0.0, x};
  line.y = {0.0, 0.0};
  job.polylines.push_back(line);
  return job;
}
}  // namespace

TEST(BadInput, NodesStayUp)
{
  ros::NodeHandle nh;
  std::vector<std::uint32_t> setpoint_jobs;
  std::vector<ScanJob> jobs;
  ros::Subscriber setpoints = nh.subscribe<NcSetpoint>(
      "nc/setpoint", 0, [&](const NcSetpoint::ConstPtr& m) { setpoint_jobs.push_back(m->chunk.job_id); });
  ros::Subscriber cam = nh.subscribe<ScanJob>("cam/job", 10, [&](const ScanJob::ConstPtr& m) { jobs.push_back(*m); });
  ros::Publisher load = nh.advertise<std_msgs::String>("cam/load", 10);
  ros::Publisher inject = nh.advertise<ScanJob>("cam/job", 10);
  ASSERT_TRUE(waitFor([&] { return load.getNumSubscribers() > 0 && inject.getNumSubscribers() > 0; }, 20.0));

  // The NC rejects these (NaN speed, a point outside the field) and publishes nothing for them.
  inject.publish(badJob(101, NAN, 0.001));
  inject.publish(badJob(102, 1.0, 0.5));
  // The CAM node rejects a bad built-in spec (its start-up file was missing too).
  std_msgs::String msg;
  msg.data = "corner:speed=-2";
  load.publish(msg);
  ros::WallDuration(0.5).sleep();
  msg.data = "corner:speed=1,angle=90";
  load.publish(msg);

  ASSERT_TRUE(waitFor([&] { return !setpoint_jobs.empty(); }, 30.0)) << "no setpoint after the good job";
  for (std::uint32_t id : setpoint_jobs)
    EXPECT_LT(id, 101u) << "a rejected job produced setpoints";
  // Only the good job was published by the CAM node (the bad ones never got an id).
  std::size_t from_cam = 0;
  for (const ScanJob& j : jobs)
    if (j.job_id < 101)
    {
      ++from_cam;
      EXPECT_EQ(j.job_id, 1u);
    }
  EXPECT_EQ(from_cam, 1u);
}

int main(int argc, char** argv)
{
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "bad_input_stays_up");
  return RUN_ALL_TESTS();
}
