/// \file ros_chunk_outlet.hpp
/// \brief A publisher that holds its messages until every expected subscriber is connected,
/// so no chunk is lost to a consumer (or a recorder) that connects late.
///
/// roscpp counts one subscriber link per subscribing process: the stages of one nodelet manager
/// that consume a topic are one link, whether one or three of them are loaded yet. So the stream
/// consumers of this process register themselves (InProcessConsumer, held by StageNodeAdapter) and
/// a topic's subscribers are its links from other processes plus the consumers registered here.
///
/// Messages are published as shared pointers to const: between nodelets in one manager roscpp
/// hands the subscribers that very message (zero copy, no serialisation); it serialises only for
/// subscribers in other processes (separate nodes, rosbag record).
#pragma once

#include <ros/ros.h>

#include <boost/make_shared.hpp>
#include <boost/shared_ptr.hpp>
#include <cstdint>
#include <deque>
#include <string>
#include <utility>

namespace scanhead
{
/// \brief One consumer of a stream topic in this process, registered for as long as it lives.
/// Construct it after subscribing (the topic's in-process link exists then), destroy it before.
class InProcessConsumer
{
public:
  /// \param[in] topic the resolved topic name (ros::Subscriber::getTopic())
  explicit InProcessConsumer(std::string topic);
  ~InProcessConsumer();
  InProcessConsumer(const InProcessConsumer&) = delete;
  InProcessConsumer& operator=(const InProcessConsumer&) = delete;

  /// \return the consumers of \p topic registered in this process
  static std::uint32_t count(const std::string& topic);

private:
  std::string topic_;
};

/// \brief The subscribers of \p publisher's topic: its links from other processes plus the
/// consumers registered in this one (all of which share one in-process link).
std::uint32_t subscribers(const ros::Publisher& publisher);

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
  void push(Message&& msg) { push(boost::make_shared<const Message>(std::move(msg))); }
  /// \brief As above, for a message already shared (not copied; nobody may change it any more).
  void push(boost::shared_ptr<const Message> msg)
  {
    pending_.push_back(std::move(msg));
    flush();
  }

  /// \brief Publishes what is held once the expected subscribers are connected.
  void flush()
  {
    if (subscribers(publisher_) < expected_)
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
  std::deque<boost::shared_ptr<const Message>> pending_;
};

/// \brief Subscribers a stream topic must have before it flows: `~subscribers` (the stage's
/// consumers, default \p consumers) plus `stream_extra_subscribers` (1 while recording a bag).
std::uint32_t expectedSubscribers(const ros::NodeHandle& nh, const ros::NodeHandle& private_nh,
                                  const std::string& param, int consumers);
}  // namespace scanhead
