/// \file ros_liveness.hpp
/// \brief Is the stream graph upstream of some topics alive? Tells a dead stage from a slow one.
///
/// Every stream is flow-controlled by the last stage's acknowledgements, so a stage that is
/// merely busy downstream (the energy node writing a big job's results) silences every stream
/// upstream of it: silence alone cannot tell a dead stage from a slow one. This asks the master
/// who publishes each topic (getSystemState) and pings each publisher's XML-RPC server
/// (lookupNode, then getPid with a short timeout: what `rosnode ping` does). A killed node's port
/// refuses the connection at once (its master registration outlives it); a stopped or
/// overloaded one accepts and does not answer. The walk goes on upstream through the stages'
/// announcements on stream/ready (each consumer's process and input topics): the publisher of a
/// topic is a process (a node, or the nodelet manager for every nodelet in it), and the inputs
/// of every stage announced by that process are walked in turn. Only stream stages announce, so
/// only the stream graph is walked. This process itself is taken as alive (not pinged).
///
/// Calls block (master queries, pings up to the ping timeout per unanswering node): call check()
/// off the hot path (after silence, at most every second or so), never from a chunk callback.
#pragma once

#include <ros/ros.h>
#include <scanhead/StageReady.h>

#include <map>
#include <mutex>
#include <set>
#include <string>
#include <vector>

namespace scanhead
{
/// \brief What check() found of the nodes publishing the stream topics upstream.
struct UpstreamLiveness
{
  std::vector<std::string> dead;        ///< "node (why)" or "topic (no publisher)": the stream cannot resume
  std::vector<std::string> unanswered;  ///< answered no ping in time: stopped, hung or overloaded
  std::vector<std::string> alive;       ///< answered (this process included)
  bool anyDead() const { return !dead.empty(); }
  /// \return the list as "a, b, c"
  static std::string join(const std::vector<std::string>& names);
};

/// \brief The result of one XML-RPC ping.
enum class PingResult
{
  Answered,    ///< getPid answered
  Unanswered,  ///< no answer within the timeout (stopped, hung, overloaded), or nothing known
               ///< (a local failure, an unusable URI, a failed name lookup): waited for, not gone
  Refused      ///< refused, reset or unreachable: no server at the URI (the process is gone)
};

/// \brief Calls getPid on the XML-RPC server at \p uri (http://host:port/) with a timeout.
PingResult pingNode(const std::string& uri, double timeout_s);

class UpstreamWatch
{
public:
  /// Subscribes stream/ready (latched: every announcement made so far).
  explicit UpstreamWatch(ros::NodeHandle& nh);
  UpstreamWatch(const UpstreamWatch&) = delete;  // its subscription calls back into this object
  UpstreamWatch& operator=(const UpstreamWatch&) = delete;

  /// \brief Walks upstream from \p topics (resolved names) and pings every publisher on the way.
  /// \param[in] ping_timeout_s how long one node may take to answer
  UpstreamLiveness check(const std::vector<std::string>& topics, double ping_timeout_s = 0.5) const;

private:
  void onReady(const StageReady& msg);

  mutable std::mutex mutex_;
  std::map<std::string, std::map<std::string, std::vector<std::string>>> inputs_;  ///< process -> node -> topics
  ros::Subscriber ready_sub_;
};

/// \brief A timeout parameter: the private `~name`, else the global `name`, else \p fallback.
double timeoutParam(const ros::NodeHandle& nh, const ros::NodeHandle& private_nh, const std::string& name,
                    double fallback);
}  // namespace scanhead
