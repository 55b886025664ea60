/// \file ros_chunk_outlet.hpp
/// \brief A publisher that holds its messages until the consumers it expects BY NAME are
/// connected, so no chunk is lost to a consumer (or a recorder) that connects late, and no extra
/// subscriber (rostopic echo, a plain node, rqt) can start a stream early or hold it back.
///
/// The handshake: every stream consumer (StageNodeAdapter) announces, once it has subscribed, its
/// node name, the process it runs in and its input topics on the latched topic stream/ready
/// (scanhead/StageReady, one message listing all the consumers of a process: ReadyAnnouncer). A producer is configured
/// with the consumers it expects per topic
/// (`~<topic>_consumers`, plus `stream_recorders` for every topic) and publishes once each of them
/// is linked to it: a link whose subscriber is that node (a standalone node, rosbag record), or an
/// announcement of that node for the topic and a link to the process it named (a nodelet: the
/// stages of one manager share one link per topic, whose caller id is the manager's). A link is
/// read from roscpp's own connection table (the caller id each subscriber sent in its header), so
/// a subscriber the producer does not expect changes nothing. While a consumer is missing the
/// messages are held (the flow window bounds them); waitedS() and missing() let the producer time
/// out with an error naming who is missing.
///
/// Messages are published as shared pointers to const: between nodelets in one manager roscpp
/// hands the subscribers that very message (zero copy, no serialisation); it serialises only for
/// subscribers in other processes (separate nodes, rosbag record).
#pragma once

#include <ros/ros.h>
#include <scanhead/StageReady.h>

#include <boost/make_shared.hpp>
#include <boost/shared_ptr.hpp>
#include <cstdint>
#include <deque>
#include <map>
#include <set>
#include <string>
#include <utility>
#include <vector>

namespace scanhead
{
/// \brief The consumers one topic's producer waits for, and whether each is linked to it.
class ConsumerGate
{
public:
  /// \param[in] topic      the resolved topic
  /// \param[in] consumers  node names (relative ones are resolved in \p nh's namespace)
  ConsumerGate(ros::NodeHandle& nh, std::string topic, const std::vector<std::string>& consumers);
  ConsumerGate(const ConsumerGate&) = delete;  // its subscription calls back into this object
  ConsumerGate& operator=(const ConsumerGate&) = delete;

  /// \return true when every expected consumer is linked (cached until the links or the
  /// announcements change, or refresh())
  bool ready(std::uint32_t links);
  /// \brief Forgets the cached verdict (a link may have changed without the count changing).
  void refresh() { checked_ = false; }
  /// \return the expected consumers not linked now, each with why ("not connected", ...)
  std::vector<std::string> missing() const;
  const std::vector<std::string>& consumers() const { return consumers_; }

private:
  void onReady(const StageReady& msg);
  /// \return the caller ids of the subscribers linked to the topic's publication in this process
  std::multiset<std::string> links() const;
  std::string whyMissing(const std::string& consumer, const std::multiset<std::string>& linked) const;

  std::string topic_;
  std::vector<std::string> consumers_;
  struct Announcement
  {
    std::string process;
    std::vector<std::string> topics;
  };
  std::map<std::string, Announcement> announced_;  ///< by consumer node name
  ros::Subscriber ready_sub_;
  bool checked_ = false, ready_ = false;
  std::uint32_t checked_links_ = 0;
};

template <class Message>
class ChunkOutlet
{
public:
  /// \param[in] consumers_param private parameter listing the expected consumers (node names, a
  ///            list or a space-separated string), default \p default_consumers; the global
  ///            `stream_recorders` are expected too
  /// \param[in] queue_size publisher queue; the flow-control window keeps the traffic below it
  ChunkOutlet(ros::NodeHandle& nh, const ros::NodeHandle& private_nh, const std::string& topic,
              const std::string& consumers_param, const std::vector<std::string>& default_consumers,
              std::uint32_t queue_size = 1000)
    : publisher_(nh.advertise<Message>(topic, queue_size))
    , gate_(nh, publisher_.getTopic(), expectedConsumers(nh, private_nh, consumers_param, default_consumers))
  {
  }

  /// \brief Publishes now if the consumers are there, else keeps the message for flush().
  void push(Message&& msg) { push(boost::make_shared<const Message>(std::move(msg))); }
  /// \brief As above, for a message already shared (not copied; nobody may change it any more).
  void push(boost::shared_ptr<const Message> msg)
  {
    pending_.push_back(std::move(msg));
    flush();
  }

  /// \brief Publishes what is held once the expected consumers are linked.
  void flush()
  {
    if (pending_.empty())
      return;
    if (!gate_.ready(publisher_.getNumSubscribers()))
    {
      if (waiting_since_.isZero())
        waiting_since_ = ros::WallTime::now();
      return;
    }
    waiting_since_ = ros::WallTime();
    while (!pending_.empty())
    {
      publisher_.publish(pending_.front());
      pending_.pop_front();
    }
  }
  /// \brief flush() after checking the links afresh (call it from a timer).
  void refresh()
  {
    gate_.refresh();
    flush();
  }
  /// \brief Drops what is held (the job it belongs to was abandoned).
  void clear()
  {
    pending_.clear();
    waiting_since_ = ros::WallTime();
  }

  /// \return seconds the held messages have waited for a missing consumer (0: none waits)
  double waitedS() const { return waiting_since_.isZero() ? 0.0 : (ros::WallTime::now() - waiting_since_).toSec(); }
  /// \return "topic: consumer (why), ..." of the consumers missing now
  std::string missingText() const
  {
    std::string text = publisher_.getTopic() + " waits for";
    for (const std::string& m : gate_.missing())
      text += " " + m;
    return text;
  }
  std::size_t pending() const { return pending_.size(); }
  ros::Publisher& publisher() { return publisher_; }

private:
  static std::vector<std::string> expectedConsumers(const ros::NodeHandle& nh, const ros::NodeHandle& private_nh,
                                                    const std::string& param,
                                                    const std::vector<std::string>& default_consumers);

  ros::Publisher publisher_;
  ConsumerGate gate_;
  std::deque<boost::shared_ptr<const Message>> pending_;
  ros::WallTime waiting_since_;  ///< zero while nothing waits
};

/// \brief A consumer's entry in its process's announcement on stream/ready, for as long as it lives.
/// Construct it after subscribing, destroy it before unsubscribing.
class ReadyAnnouncer
{
public:
  /// \param[in] node   the consumer's node name (resolved)
  /// \param[in] topics its resolved input topics
  ReadyAnnouncer(ros::NodeHandle& nh, const std::string& node, const std::vector<std::string>& topics);
  ~ReadyAnnouncer();
  ReadyAnnouncer(const ReadyAnnouncer&) = delete;
  ReadyAnnouncer& operator=(const ReadyAnnouncer&) = delete;

private:
  /// \brief Publishes the process's whole list (the latched message is the last one published).
  void publish();

  std::string node_;
  ros::Publisher publisher_;
};

/// \brief A node-name list parameter: an XML-RPC list of strings or one space/comma-separated
/// string; \p fallback when unset.
std::vector<std::string> nameListParam(const ros::NodeHandle& nh, const std::string& param,
                                       const std::vector<std::string>& fallback);

template <class Message>
std::vector<std::string> ChunkOutlet<Message>::expectedConsumers(const ros::NodeHandle& nh,
                                                                 const ros::NodeHandle& private_nh,
                                                                 const std::string& param,
                                                                 const std::vector<std::string>& default_consumers)
{
  std::vector<std::string> names = nameListParam(private_nh, param, default_consumers);
  for (const std::string& recorder : nameListParam(nh, "stream_recorders", {}))
    names.push_back(recorder);
  return names;
}
}  // namespace scanhead
