// The last stage stalls, then runs slowly: the NC stops at its window while nothing is
// acknowledged, and afterwards every sample arrives, in order. The test node is the last stage
// and subscribes to nothing else, so the stages' subscriber counts are the launch's own.
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <scanhead/ChunkAck.h>
#include <scanhead/SpotStream.h>

using namespace scanhead;

TEST(FlowControl, StalledThenSlowConsumerLosesNothing)
{
  ros::NodeHandle nh;
  ros::Publisher ack_pub = nh.advertise<ChunkAck>("energy/ack", 100, true);  // latched, as the energy node
  std::uint64_t next = 0, total = 0, gaps = 0;
  std::uint32_t job_id = 0;
  bool acking = false;
  auto ack = [&] {
    ChunkAck msg;
    msg.job_id = job_id;
    msg.next_index = next;
    ack_pub.publish(msg);
  };
  ros::Subscriber spots = nh.subscribe<SpotStream>("optics/spot", 0, [&](const SpotStream::ConstPtr& m) {
    if (m->chunk.first_index != next)
      ++gaps;
    next = m->chunk.first_index + m->power.size();
    total = m->chunk.total_samples;
    job_id = m->chunk.job_id;
    if (acking)
    {
      ros::WallDuration(0.02).sleep();  // the slow consumer
      ack();
    }
  });
  auto spinFor = [&](double seconds, const std::function<bool()>& done) {
    const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(seconds);
    while (!done() && ros::ok() && ros::WallTime::now() < deadline)
    {
      ros::spinOnce();
      ros::WallDuration(0.001).sleep();
    }
  };
  // Stall: nothing acknowledged. The NC may run stream.window_chunks (4) × 50 samples ahead.
  spinFor(30.0, [&] { return next > 0; });
  ASSERT_GT(next, 0u) << "no spot chunk arrived";
  spinFor(1.0, [] { return false; });
  const std::uint64_t stalled_at = next;
  EXPECT_EQ(stalled_at, 4u * 50u) << "the NC did not stop at its window while unacknowledged";

  // Slow consumer: 20 ms per chunk, acknowledged; the whole job arrives without a gap.
  acking = true;
  ack();
  spinFor(100.0, [&] { return total > 0 && next >= total; });
  EXPECT_EQ(next, total);
  EXPECT_EQ(gaps, 0u);
  EXPECT_GT(total, 20u * 50u);  // the job spans many windows
  std::printf("stalled at %llu samples (window 200); then %llu samples in order, no gap\n",
              static_cast<unsigned long long>(stalled_at), static_cast<unsigned long long>(total));
}

int main(int argc, char** argv)
{
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "flow_control_test");
  return RUN_ALL_TESTS();
}
