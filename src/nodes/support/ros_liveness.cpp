#include "ros_liveness.hpp"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netdb.h>
#include <poll.h>
#include <ros/master.h>
#include <ros/this_node.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <deque>
#include <sstream>

namespace scanhead
{
std::string UpstreamLiveness::join(const std::vector<std::string>& names)
{
  std::string text;
  for (const std::string& n : names)
    text += (text.empty() ? "" : ", ") + n;
  return text;
}

namespace
{
using Clock = std::chrono::steady_clock;

/// \brief Closes the socket on every path.
struct Socket
{
  int fd = -1;
  ~Socket()
  {
    if (fd >= 0)
      ::close(fd);
  }
};

int msLeft(Clock::time_point deadline)
{
  const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count();
  return left > 0 ? static_cast<int>(left) : 0;
}

/// \return true if \p fd became ready for \p events before \p deadline
bool waitFor(int fd, short events, Clock::time_point deadline)
{
  pollfd p{fd, events, 0};
  for (;;)
  {
    const int n = ::poll(&p, 1, msLeft(deadline));
    if (n > 0)
      return true;
    if (n == 0 || errno != EINTR)
      return false;
  }
}

/// \brief What a failed socket call with \p error says about the node: only a refusal or an
/// unreachable host means it is gone; any other failure (ours: no descriptor left, no buffer) says
/// nothing, and a node we cannot judge is waited for like a silent one (up to hang_timeout_s).
PingResult failure(int error)
{
  switch (error)
  {
    case ECONNREFUSED:
    case ECONNRESET:
    case EPIPE:
    case EHOSTUNREACH:
    case ENETUNREACH:
      return PingResult::Refused;
    default:
      return PingResult::Unanswered;
  }
}

/// \brief One connection attempt and getPid call on \p address.
PingResult pingAddress(const addrinfo& address, const std::string& host_port, Clock::time_point deadline)
{
  Socket s;
  s.fd = ::socket(address.ai_family, address.ai_socktype | SOCK_NONBLOCK | SOCK_CLOEXEC, address.ai_protocol);
  if (s.fd < 0)
    return PingResult::Unanswered;  // out of descriptors here: nothing known about the node
  if (::connect(s.fd, address.ai_addr, address.ai_addrlen) != 0)
  {
    if (errno != EINPROGRESS)
      return failure(errno);
    if (!waitFor(s.fd, POLLOUT, deadline))
      return PingResult::Unanswered;
    int error = 0;
    socklen_t length = sizeof(error);
    if (::getsockopt(s.fd, SOL_SOCKET, SO_ERROR, &error, &length) != 0)
      return PingResult::Unanswered;
    if (error != 0)
      return failure(error);
  }
  const std::string body = "<?xml version=\"1.0\"?><methodCall><methodName>getPid</methodName><params><param><value>" +
                           ros::this_node::getName() + "</value></param></params></methodCall>";
  const std::string request = "POST / HTTP/1.1\r\nUser-Agent: scanhead\r\nHost: " + host_port +
                              "\r\nContent-Type: text/xml\r\nContent-length: " + std::to_string(body.size()) +
                              "\r\n\r\n" + body;
  for (std::size_t sent = 0; sent < request.size();)
  {
    if (!waitFor(s.fd, POLLOUT, deadline))
      return PingResult::Unanswered;
    const ssize_t n = ::send(s.fd, request.data() + sent, request.size() - sent, MSG_NOSIGNAL);
    if (n < 0 && errno != EAGAIN && errno != EINTR)
      return failure(errno);
    sent += n > 0 ? static_cast<std::size_t>(n) : 0;
  }
  // The status line is enough: the server's thread is running and answering.
  std::string reply;
  char buffer[256];
  while (reply.size() < 12)
  {
    if (!waitFor(s.fd, POLLIN, deadline))
      return PingResult::Unanswered;
    const ssize_t n = ::recv(s.fd, buffer, sizeof(buffer), 0);
    if (n == 0)
      return PingResult::Refused;  // closed without an answer: the process is going away
    if (n < 0 && errno != EAGAIN && errno != EINTR)
      return failure(errno);
    if (n > 0)
      reply.append(buffer, static_cast<std::size_t>(n));
  }
  // Something answers, if not XML-RPC: a process is there, so not known to be gone.
  return reply.compare(0, 5, "HTTP/") == 0 ? PingResult::Answered : PingResult::Unanswered;
}
}  // namespace

PingResult pingNode(const std::string& uri, double timeout_s)
{
  // http://host:port/ (roscpp and rospy both advertise this form)
  const std::string scheme = "http://";
  // An address this check cannot use says nothing about the node: waited for, not declared gone.
  if (uri.compare(0, scheme.size(), scheme) != 0)
    return PingResult::Unanswered;
  const std::string rest = uri.substr(scheme.size());
  const std::string host_port = rest.substr(0, rest.find('/'));
  const std::size_t colon = host_port.rfind(':');
  if (colon == std::string::npos)
    return PingResult::Unanswered;
  const std::string host = host_port.substr(0, colon), port = host_port.substr(colon + 1);
  const Clock::time_point deadline =
      Clock::now() + std::chrono::microseconds(static_cast<long long>(std::max(0.0, timeout_s) * 1e6));
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  addrinfo* found = nullptr;
  if (::getaddrinfo(host.c_str(), port.c_str(), &hints, &found) != 0 || found == nullptr)
    return PingResult::Unanswered;  // a name lookup failing now (EAI_AGAIN) is not a death
  PingResult result = PingResult::Refused;
  for (const addrinfo* a = found; a != nullptr && result == PingResult::Refused; a = a->ai_next)
    result = pingAddress(*a, host_port, deadline);
  ::freeaddrinfo(found);
  return result;
}

UpstreamWatch::UpstreamWatch(ros::NodeHandle& nh)
{
  ready_sub_ = nh.subscribe("stream/ready", 100, &UpstreamWatch::onReady, this);
}

void UpstreamWatch::onReady(const StageReady& msg)
{
  std::lock_guard<std::mutex> lock(mutex_);
  auto& nodes = inputs_[msg.process];
  nodes.clear();  // the process's whole list: a stage missing from it went away
  for (std::size_t i = 0; i < msg.nodes.size(); ++i)
  {
    std::vector<std::string>& topics = nodes[msg.nodes[i]];
    std::istringstream words(i < msg.topics.size() ? msg.topics[i] : std::string());
    for (std::string topic; words >> topic;)
      topics.push_back(topic);
  }
}

UpstreamLiveness UpstreamWatch::check(const std::vector<std::string>& topics, double ping_timeout_s) const
{
  UpstreamLiveness out;
  const std::string self = ros::this_node::getName();
  XmlRpc::XmlRpcValue args, result, payload;
  args[0] = self;
  if (!ros::master::execute("getSystemState", args, result, payload, false))
  {
    out.unanswered.push_back("the ROS master");
    return out;
  }
  std::map<std::string, std::vector<std::string>> publishers;  // topic -> nodes
  for (int i = 0; i < payload[0].size(); ++i)
  {
    std::vector<std::string>& nodes = publishers[static_cast<std::string>(payload[0][i][0])];
    for (int j = 0; j < payload[0][i][1].size(); ++j)
      nodes.push_back(static_cast<std::string>(payload[0][i][1][j]));
  }
  std::deque<std::string> queue(topics.begin(), topics.end());
  std::set<std::string> seen_topics(topics.begin(), topics.end()), seen_nodes;
  while (!queue.empty())
  {
    const std::string topic = queue.front();
    queue.pop_front();
    const auto pub = publishers.find(topic);
    if (pub == publishers.end() || pub->second.empty())
    {
      out.dead.push_back(topic + " (no publisher left)");
      continue;
    }
    for (const std::string& node : pub->second)
    {
      if (!seen_nodes.insert(node).second)
        continue;
      if (node == self)
        out.alive.push_back(node);
      else
      {
        XmlRpc::XmlRpcValue lookup_args, lookup_result, uri;
        lookup_args[0] = self;
        lookup_args[1] = node;
        if (!ros::master::execute("lookupNode", lookup_args, lookup_result, uri, false))
        {
          out.dead.push_back(node + " (not registered)");
          continue;
        }
        switch (pingNode(static_cast<std::string>(uri), ping_timeout_s))
        {
          case PingResult::Answered:
            out.alive.push_back(node);
            break;
          case PingResult::Unanswered:
            out.unanswered.push_back(node);
            break;
          case PingResult::Refused:
            out.dead.push_back(node + " (gone: " + static_cast<std::string>(uri) + " refuses connections)");
            continue;  // what feeds a dead node no longer matters
        }
      }
      // Upstream of this process: the inputs of every stage it announced.
      std::lock_guard<std::mutex> lock(mutex_);
      const auto process = inputs_.find(node);
      if (process == inputs_.end())
        continue;
      for (const auto& [stage, inputs] : process->second)
        for (const std::string& t : inputs)
          if (seen_topics.insert(t).second)
            queue.push_back(t);
    }
  }
  return out;
}

double timeoutParam(const ros::NodeHandle& nh, const ros::NodeHandle& private_nh, const std::string& name,
                    double fallback)
{
  double global = fallback, value = fallback;
  nh.param(name, global, fallback);
  private_nh.param(name, value, global);
  return value;
}
}  // namespace scanhead
