#include "ros_chunk_outlet.hpp"

#include <ros/names.h>
#include <ros/publication.h>
#include <ros/this_node.h>
#include <ros/topic_manager.h>

#include <algorithm>
#include <mutex>
#include <sstream>

namespace scanhead
{
ConsumerGate::ConsumerGate(ros::NodeHandle& nh, std::string topic, const std::vector<std::string>& consumers)
  : topic_(std::move(topic))
{
  for (const std::string& name : consumers)
    if (!name.empty())
      consumers_.push_back(ros::names::resolve(nh.getNamespace(), name, false));
  // Every announcement (latched: also those made before this producer started), 100 deep: a
  // whole graph's consumers at once.
  ready_sub_ = nh.subscribe("stream/ready", 100, &ConsumerGate::onReady, this);
}

void ConsumerGate::onReady(const StageReady& msg)
{
  // The process's whole list: a consumer of that process missing from it went away.
  for (auto& [node, a] : announced_)
    if (a.process == msg.process)
      a.topics.clear();
  for (std::size_t i = 0; i < msg.nodes.size(); ++i)
  {
    Announcement& a = announced_[msg.nodes[i]];
    a.process = msg.process;
    a.topics.clear();
    std::istringstream words(i < msg.topics.size() ? msg.topics[i] : std::string());
    for (std::string topic; words >> topic;)
      a.topics.push_back(topic);
  }
  checked_ = false;
}

namespace
{
std::mutex announce_mutex;
std::map<std::string, std::string>& announced()  // this process's consumers: node -> topics
{
  static std::map<std::string, std::string> consumers;
  return consumers;
}
}  // namespace

ReadyAnnouncer::ReadyAnnouncer(ros::NodeHandle& nh, const std::string& node, const std::vector<std::string>& topics)
  : node_(node)
  , publisher_(nh.advertise<StageReady>("stream/ready", 1, true))
{
  std::string text;
  for (const std::string& t : topics)
    text += (text.empty() ? "" : " ") + t;
  std::lock_guard<std::mutex> lock(announce_mutex);
  announced()[node_] = text;
  publish();
}

ReadyAnnouncer::~ReadyAnnouncer()
{
  std::lock_guard<std::mutex> lock(announce_mutex);
  announced().erase(node_);
  publish();  // a nodelet unloaded from a manager that stays up: its producers stop waiting for it
}

void ReadyAnnouncer::publish()
{
  StageReady msg;
  msg.process = ros::this_node::getName();
  for (const auto& [node, topics] : announced())
  {
    msg.nodes.push_back(node);
    msg.topics.push_back(topics);
  }
  publisher_.publish(msg);
}

std::multiset<std::string> ConsumerGate::links() const
{
  std::multiset<std::string> linked;
  const ros::PublicationPtr publication = ros::TopicManager::instance()->lookupPublication(topic_);
  if (!publication)
    return linked;
  // roscpp's own connection table: [id, subscriber's caller id, direction, transport, topic, ...]
  XmlRpc::XmlRpcValue info;
  info.setSize(0);
  publication->getInfo(info);
  for (int i = 0; i < info.size(); ++i)
    linked.insert(static_cast<std::string>(info[i][1]));
  return linked;
}

std::string ConsumerGate::whyMissing(const std::string& consumer, const std::multiset<std::string>& linked) const
{
  if (linked.count(consumer) != 0)
    return {};  // a standalone node or a recorder, linked under its own name
  const auto it = announced_.find(consumer);
  if (it == announced_.end())
    return "not connected, not announced on stream/ready";
  const Announcement& a = it->second;
  if (std::find(a.topics.begin(), a.topics.end(), topic_) == a.topics.end())
    return a.topics.empty() ? "went away (stream/ready)" : "announced without subscribing to this topic";
  if (linked.count(a.process) == 0)
    return "announced, but its process " + a.process + " is not connected yet";
  return {};
}

bool ConsumerGate::ready(std::uint32_t links_now)
{
  if (checked_ && links_now == checked_links_)
    return ready_;
  const std::multiset<std::string> linked = links();
  ready_ = std::all_of(consumers_.begin(), consumers_.end(),
                       [&](const std::string& c) { return whyMissing(c, linked).empty(); });
  checked_ = true;
  checked_links_ = links_now;
  return ready_;
}

std::vector<std::string> ConsumerGate::missing() const
{
  const std::multiset<std::string> linked = links();
  std::vector<std::string> out;
  for (const std::string& c : consumers_)
  {
    const std::string why = whyMissing(c, linked);
    if (!why.empty())
      out.push_back(c + " (" + why + ")");
  }
  return out;
}

std::vector<std::string> nameListParam(const ros::NodeHandle& nh, const std::string& param,
                                       const std::vector<std::string>& fallback)
{
  XmlRpc::XmlRpcValue value;
  if (!nh.getParam(param, value))
    return fallback;
  std::vector<std::string> names;
  if (value.getType() == XmlRpc::XmlRpcValue::TypeArray)
  {
    for (int i = 0; i < value.size(); ++i)
      if (value[i].getType() == XmlRpc::XmlRpcValue::TypeString)
        names.push_back(static_cast<std::string>(value[i]));
  }
  else if (value.getType() == XmlRpc::XmlRpcValue::TypeString)
  {
    std::string text = static_cast<std::string>(value);
    std::replace(text.begin(), text.end(), ',', ' ');
    std::istringstream words(text);
    for (std::string word; words >> word;)
      names.push_back(word);
  }
  else
    ROS_WARN("%s: expected a list of node names; using the default", nh.resolveName(param).c_str());
  return names;
}
}  // namespace scanhead
