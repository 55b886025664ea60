/// \file ros_chunk_outlet.hpp
/// \brief A publisher that holds its messages until every expected subscriber is connected,
/// so no chunk is lost to a consumer (or a recorder) that connects late.
#pragma once

#include <ros/ros.h>

#include <deque>
#include <string>

namespace scanhead
{
template <class Message>
class ChunkOutlet
{
public:
  /// \param[in] queue_size publisher queue; the flow-control window keeps the traffic below it
  ChunkOutlet(ros::NodeHandle& nh, const std::string& topic, std::uint32_t expected_subscribers,
              std::uint32_t queue_size = 1000, bool latch = false)
    : publisher_(nh.advertise<Message>(topic, queue_size, latch))
    , expected_(expected_subscribers)
  {
  }

  /// \brief Publishes now if the subscribers are there, else keeps the message for flush().
  void push(const Message& msg)
  {
    pending_.push_back(msg);
    flush();
  }

  /// \brief Publishes what is held once the expected subscribers are connected.
  void flush()
  {
    if (publisher_.getNumSubscribers() < expected_)
      return;
    while (!pending_.empty())
    {
      publisher_.publish(pending_.front());
      pending_.pop_front();
    }
  }

  std::size_t pending() const { return pending_.size(); }
  ros::Publisher& publisher() { return publisher_; }

private:
  ros::Publisher publisher_;
  std::uint32_t expected_;
  std::deque<Message> pending_;
};

/// \brief Subscribers a stream topic must have before it flows: `~subscribers` (the stage's
/// consumers, default \p consumers) plus `stream_extra_subscribers` (1 while recording a bag).
std::uint32_t expectedSubscribers(const ros::NodeHandle& nh, const ros::NodeHandle& private_nh,
                                  const std::string& param, int consumers);
}  // namespace scanhead
