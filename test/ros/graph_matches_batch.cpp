// Runs the live graph's job again in process and compares the metrics.yaml texts byte for byte.
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <scanhead/JobMetrics.h>

#include <sstream>

#include "ros_config.hpp"
#include "scanhead/chain/batch_chain.hpp"
#include "scanhead/chain/config_io.hpp"
#include "scanhead/job/job_files.hpp"
#include "scanhead/metrics/metrics_report.hpp"

using namespace scanhead;

TEST(GraphMatchesBatch, IdenticalMetrics)
{
  ros::NodeHandle nh, private_nh("~");
  JobMetrics::ConstPtr graph;
  ros::Subscriber sub =
      nh.subscribe<JobMetrics>("energy/metrics", 1, [&](const JobMetrics::ConstPtr& m) { graph = m; });
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(100.0);
  while (!graph && ros::ok() && ros::WallTime::now() < deadline)
  {
    ros::spinOnce();
    ros::WallDuration(0.01).sleep();
  }
  ASSERT_TRUE(graph) << "no energy/metrics from the graph";
  EXPECT_EQ(graph->dropped_samples, 0u);

  // The same config the graph used (parameter server), plus the reference's own chunking.
  ChainConfig config = chainConfigFromParams(nh);
  std::string batch_overrides;
  private_nh.param("batch_overrides", batch_overrides, std::string());
  if (!batch_overrides.empty())
  {
    std::istringstream words(batch_overrides);
    for (std::string assignment; words >> assignment;)
    {
      FlatConfig flat = flattenYaml(chainConfigToYaml(config), "graph config");
      applyOverride(flat, assignment);
      config = chainConfigFromFlat(flat);
    }
  }
  std::string job_spec;
  private_nh.param("job", job_spec, std::string("corner"));
  const auto optics = opticalModelFromParams(nh, config.optics);
  BatchChain chain(config, *optics);
  const RunMetrics batch = chain.run(loadJob(job_spec, config.cam));
  EXPECT_EQ(graph->metrics_yaml, metricsToYaml(batch));
  EXPECT_EQ(graph->samples, batch.samples);
}

int main(int argc, char** argv)
{
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "graph_matches_batch");
  return RUN_ALL_TESTS();
}
