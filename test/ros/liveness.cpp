// The liveness checks that tell a dead stage from a slow one (ros_liveness.hpp), against real
// processes: a socket nobody listens on, one that accepts and never answers, the master, and a
// publisher node that is stopped, continued and killed.
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <ros/master.h>
#include <ros/ros.h>
#include <scanhead/StageReady.h>
#include <signal.h>
#include <std_msgs/Empty.h>
#include <sys/socket.h>
#include <unistd.h>
#include <xmlrpcpp/XmlRpcClient.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <functional>

#include "ros_liveness.hpp"

using namespace scanhead;

namespace
{
/// \brief A bound TCP socket on 127.0.0.1 (listening if asked): its URI.
struct LocalSocket
{
  int fd = -1;
  std::string uri;
  explicit LocalSocket(bool listening)
  {
    fd = ::socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    ::bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof(a));
    socklen_t n = sizeof(a);
    ::getsockname(fd, reinterpret_cast<sockaddr*>(&a), &n);
    if (listening)
      ::listen(fd, 4);
    uri = "http://127.0.0.1:" + std::to_string(ntohs(a.sin_port)) + "/";
  }
  ~LocalSocket() { ::close(fd); }
};

double secondsOf(const std::function<void()>& f)
{
  const auto t0 = std::chrono::steady_clock::now();
  f();
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

bool contains(const std::vector<std::string>& v, const std::string& prefix)
{
  return std::any_of(v.begin(), v.end(), [&](const std::string& s) { return s.rfind(prefix, 0) == 0; });
}

void spinFor(double seconds)
{
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(seconds);
  while (ros::WallTime::now() < end)
  {
    ros::spinOnce();
    ros::WallDuration(0.01).sleep();
  }
}
}  // namespace

TEST(Liveness, PingTellsAnsweringStoppedAndGone)
{
  PingResult r{};
  // Bound, not listening: the kernel refuses at once (what a killed node's port does).
  LocalSocket closed(false);
  EXPECT_LT(secondsOf([&] { r = pingNode(closed.uri, 2.0); }), 0.2);
  EXPECT_EQ(r, PingResult::Refused);
  // Listening, never answering (a stopped process): the connection is accepted, no reply.
  LocalSocket silent(true);
  const double waited = secondsOf([&] { r = pingNode(silent.uri, 0.3); });
  EXPECT_EQ(r, PingResult::Unanswered);
  EXPECT_GE(waited, 0.29);
  EXPECT_LT(waited, 0.6);
  // The master answers getPid like any node.
  EXPECT_EQ(pingNode(ros::master::getURI(), 2.0), PingResult::Answered);
  // What the check cannot use says nothing of the node: waited for (hang_timeout_s), never "gone".
  EXPECT_EQ(pingNode("not a uri", 0.1), PingResult::Unanswered);
  EXPECT_EQ(pingNode("http://no-such-host.invalid:1234/", 0.5), PingResult::Unanswered);
}

TEST(Liveness, UpstreamWalkFindsStoppedAndKilledPublisher)
{
  ros::NodeHandle nh;
  UpstreamWatch watch(nh);
  // This process announces a stage whose input is /liveness/upstream, and publishes
  // /liveness/downstream: the walk from downstream reaches the rostopic publisher through it.
  ros::Publisher ready = nh.advertise<StageReady>("stream/ready", 1, true);
  ros::Publisher downstream = nh.advertise<std_msgs::Empty>("/liveness/downstream", 1);
  StageReady announce;
  announce.process = ros::this_node::getName();
  announce.nodes.push_back(ros::this_node::getName() + "/stage");
  announce.topics.push_back("/liveness/upstream");
  ready.publish(announce);
  const std::string publisher = "/liveness_publisher";
  UpstreamLiveness live;
  for (int i = 0; i < 100 && !contains(live.alive, publisher); ++i)  // rostopic pub starts, the announcement arrives
  {
    spinFor(0.1);
    live = watch.check({"/liveness/downstream"}, 0.5);
  }
  ASSERT_TRUE(contains(live.alive, publisher)) << "alive: " << UpstreamLiveness::join(live.alive);
  EXPECT_TRUE(contains(live.alive, ros::this_node::getName()));
  EXPECT_FALSE(live.anyDead()) << UpstreamLiveness::join(live.dead);

  // The publisher's process, as it tells its XML-RPC server.
  XmlRpc::XmlRpcValue args, result, uri;
  args[0] = ros::this_node::getName();
  args[1] = publisher;
  ASSERT_TRUE(ros::master::execute("lookupNode", args, result, uri, false));
  std::string host = static_cast<std::string>(uri);
  XmlRpc::XmlRpcValue pid_args, pid_result;
  pid_args[0] = ros::this_node::getName();
  int port = 0;
  ASSERT_EQ(std::sscanf(host.c_str(), "http://%*[^:]:%d", &port), 1);
  XmlRpc::XmlRpcClient node("127.0.0.1", port, "/");
  ASSERT_TRUE(node.execute("getPid", pid_args, pid_result));
  const pid_t pid = static_cast<int>(pid_result[2]);
  ASSERT_GT(pid, 0);

  // Stopped: not gone, not answering; the check takes about the ping timeout.
  ASSERT_EQ(::kill(pid, SIGSTOP), 0);
  const double waited = secondsOf([&] { live = watch.check({"/liveness/downstream"}, 0.3); });
  ::kill(pid, SIGCONT);
  EXPECT_TRUE(contains(live.unanswered, publisher)) << "unanswered: " << UpstreamLiveness::join(live.unanswered);
  EXPECT_FALSE(live.anyDead()) << UpstreamLiveness::join(live.dead);
  EXPECT_LT(waited, 1.0);
  // Continued: alive again.
  live = watch.check({"/liveness/downstream"}, 0.5);
  EXPECT_TRUE(contains(live.alive, publisher));
  // Killed: its registration outlives it, its port refuses: gone, named, found at once.
  ASSERT_EQ(::kill(pid, SIGKILL), 0);
  spinFor(0.3);
  const double found = secondsOf([&] { live = watch.check({"/liveness/downstream"}, 2.0); });
  EXPECT_TRUE(contains(live.dead, publisher + " (gone")) << "dead: " << UpstreamLiveness::join(live.dead);
  EXPECT_LT(found, 0.5);
  // A topic nobody publishes: gone too.
  live = watch.check({"/liveness/nobody"}, 0.5);
  EXPECT_TRUE(contains(live.dead, "/liveness/nobody (no publisher left)"));
  std::printf("stopped publisher: unanswered after %.2f s (ping timeout 0.3 s); killed: gone in %.3f s\n", waited,
              found);
}

int main(int argc, char** argv)
{
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "liveness_test");
  ros::NodeHandle nh;  // starts the node (XML-RPC server) for the whole test
  return RUN_ALL_TESTS();
}
