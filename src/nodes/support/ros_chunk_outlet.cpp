#include "ros_chunk_outlet.hpp"

namespace scanhead
{
std::uint32_t expectedSubscribers(const ros::NodeHandle& nh, const ros::NodeHandle& private_nh,
                                  const std::string& param, int consumers)
{
  int extra = 0;
  private_nh.param(param, consumers, consumers);
  nh.param("stream_extra_subscribers", extra, 0);
  return static_cast<std::uint32_t>(std::max(0, consumers) + std::max(0, extra));
}
}  // namespace scanhead
