#include "ros_chunk_outlet.hpp"

#include <algorithm>
#include <map>
#include <mutex>

namespace scanhead
{
namespace
{
std::mutex registry_mutex;
std::map<std::string, std::uint32_t>& registry()
{
  static std::map<std::string, std::uint32_t> consumers;  // by resolved topic
  return consumers;
}
}  // namespace

InProcessConsumer::InProcessConsumer(std::string topic)
  : topic_(std::move(topic))
{
  std::lock_guard<std::mutex> lock(registry_mutex);
  ++registry()[topic_];
}

InProcessConsumer::~InProcessConsumer()
{
  std::lock_guard<std::mutex> lock(registry_mutex);
  if (--registry()[topic_] == 0)
    registry().erase(topic_);
}

std::uint32_t InProcessConsumer::count(const std::string& topic)
{
  std::lock_guard<std::mutex> lock(registry_mutex);
  const auto it = registry().find(topic);
  return it == registry().end() ? 0 : it->second;
}

std::uint32_t subscribers(const ros::Publisher& publisher)
{
  const std::uint32_t links = publisher.getNumSubscribers();
  const std::uint32_t here = InProcessConsumer::count(publisher.getTopic());
  // The registered consumers share one of the links (the in-process one).
  return links == 0 ? 0 : links + (here > 0 ? here - 1 : 0);
}

std::uint32_t expectedSubscribers(const ros::NodeHandle& nh, const ros::NodeHandle& private_nh,
                                  const std::string& param, int consumers)
{
  int extra = 0;
  private_nh.param(param, consumers, consumers);
  nh.param("stream_extra_subscribers", extra, 0);
  return static_cast<std::uint32_t>(std::max(0, consumers) + std::max(0, extra));
}
}  // namespace scanhead
