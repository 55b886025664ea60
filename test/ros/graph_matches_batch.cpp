// Runs the live graph's job again in process and compares the metrics.yaml texts byte for byte;
// and checks the graph ran as the launch said: every stream published by the one nodelet manager
// (~manager set), or each by its own stage node (~manager empty), or the ~standalone_stages by
// their own node and the others by the manager.
#include <gtest/gtest.h>
#include <ros/master.h>
#include <ros/ros.h>
#include <scanhead/JobMetrics.h>

#include <set>
#include <sstream>
#include <string>

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

namespace
{
/// The nodes that publish \p topic, as the master knows them (its getSystemState).
std::set<std::string> publishersOf(const std::string& topic)
{
  XmlRpc::XmlRpcValue request, response, payload;
  request[0] = ros::this_node::getName();
  std::set<std::string> nodes;
  if (!ros::master::execute("getSystemState", request, response, payload, true))
    return nodes;
  XmlRpc::XmlRpcValue& publishers = payload[0];
  for (int i = 0; i < publishers.size(); ++i)
    if (static_cast<std::string>(publishers[i][0]) == topic)
      for (int j = 0; j < publishers[i][1].size(); ++j)
        nodes.insert(static_cast<std::string>(publishers[i][1][j]));
  return nodes;
}
}  // namespace

TEST(GraphMatchesBatch, StagesWhereTheLaunchPutThem)
{
  ros::NodeHandle nh, private_nh("~");
  std::string manager, standalone_text;
  private_nh.param("manager", manager, std::string());
  // Stages run as their own process beside the manager (a standalone NC feeding nodelets).
  private_nh.param("standalone_stages", standalone_text, std::string());
  std::set<std::string> standalone;
  std::istringstream words(standalone_text);
  for (std::string word; words >> word;)
    standalone.insert(word);
  // The stream each stage publishes, by the stage's node name.
  const std::pair<const char*, const char*> streams[] = {{"nc/setpoint", "nc_interpolator"},
                                                         {"galvo/joint_states_chunk", "galvo_servo"},
                                                         {"optics/spot", "optical_chain"},
                                                         {"energy/ack", "energy_accumulator"}};
  for (const auto& [topic, node] : streams)
  {
    const bool own_process = manager.empty() || standalone.count(node) != 0;
    const std::set<std::string> expected{ros::names::resolve(own_process ? std::string(node) : manager)};
    std::set<std::string> publishers = publishersOf(nh.resolveName(topic));
    // Wait for the registration only if this test runs alone (after IdenticalMetrics all are up).
    for (const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(30.0);
         publishers != expected && ros::WallTime::now() < deadline; publishers = publishersOf(nh.resolveName(topic)))
      ros::WallDuration(0.1).sleep();
    EXPECT_EQ(publishers, expected) << topic;
  }
}

int main(int argc, char** argv)
{
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "graph_matches_batch");
  return RUN_ALL_TESTS();
}
