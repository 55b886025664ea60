// A slow last stage: every sample still arrives, in order, and the NC never runs further
// ahead of the acknowledgements than its window.
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <scanhead/ChunkAck.h>
#include <scanhead/NcSetpoint.h>
#include <scanhead/SpotStream.h>

using namespace scanhead;

TEST(FlowControl, SlowConsumerLosesNothing)
{
  ros::NodeHandle nh;
  ros::Publisher ack_pub = nh.advertise<ChunkAck>("energy/ack", 100, true);  // latched, as the energy node
  std::uint64_t next = 0, total = 0, gaps = 0, acked = 0, max_ahead = 0;
  bool done = false;
  ros::Subscriber spots = nh.subscribe<SpotStream>("optics/spot", 0, [&](const SpotStream::ConstPtr& m) {
    ros::WallDuration(0.02).sleep();  // the slow consumer
    if (m->chunk.first_index != next)
      ++gaps;
    next = m->chunk.first_index + m->power.size();
    total = m->chunk.total_samples;
    ChunkAck ack;
    ack.job_id = m->chunk.job_id;
    ack.next_index = acked = next;
    ack_pub.publish(ack);
    done = next >= total;
  });
  ros::Subscriber setpoints = nh.subscribe<NcSetpoint>("nc/setpoint", 0, [&](const NcSetpoint::ConstPtr& m) {
    const std::uint64_t end = m->chunk.first_index + m->trajectory.points.size();
    max_ahead = std::max(max_ahead, end - std::min(end, acked));
  });
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(100.0);
  while (!done && ros::ok() && ros::WallTime::now() < deadline)
  {
    ros::spinOnce();
    ros::WallDuration(0.001).sleep();
  }
  ASSERT_TRUE(done) << "stream ended at sample " << next << " of " << total;
  EXPECT_EQ(gaps, 0u);
  EXPECT_EQ(next, total);
  EXPECT_GT(total, 20u * 50u);  // the job spans many windows
  // window_chunks (4) × chunk_samples (50), plus one chunk published on the ack that frees it.
  EXPECT_LE(max_ahead, 5u * 50u);
  std::printf("%llu samples in order; NC at most %llu samples ahead of the consumer\n",
              static_cast<unsigned long long>(total), static_cast<unsigned long long>(max_ahead));
}

int main(int argc, char** argv)
{
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "flow_control_test");
  return RUN_ALL_TESTS();
}
