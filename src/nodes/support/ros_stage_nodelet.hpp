/// \file ros_stage_nodelet.hpp
/// \brief The shared nodelet of every stage: the same node class as the stage's standalone
/// executable (ros_node_main.hpp), constructed from the nodelet's handles instead of a process's.
///
/// The node gets the nodelet's single-threaded handles (getNodeHandle, getPrivateNodeHandle): the
/// manager runs one nodelet's callbacks one at a time and in arrival order, whatever its
/// num_worker_threads, so a node class written for ros::spin() needs no locks, and the stages of
/// one manager still run in parallel with each other. Messages between nodelets of one manager
/// pass as shared pointers (ChunkOutlet, StageNodeAdapter): no copy, no serialisation.
///
/// One difference with a process remains: the manager constructs a nodelet on its load-service
/// thread while its worker threads already run callbacks, so a latched message (cam/job) could
/// reach a node whose constructor has not finished. The node's handles therefore queue into a
/// gate that holds every callback until the constructor has returned, as ros::spin() would.
#pragma once

#include <nodelet/nodelet.h>
#include <ros/callback_queue_interface.h>
#include <ros/ros.h>

#include <cstdint>
#include <exception>
#include <memory>
#include <mutex>
#include <utility>
#include <vector>

namespace scanhead
{
/// \brief A callback queue that holds what it is given until open(), then forwards it, in order,
/// to the target queue (and everything after it, at once).
class CallbackGate : public ros::CallbackQueueInterface
{
public:
  explicit CallbackGate(ros::CallbackQueueInterface& target)
    : target_(target)
  {
  }

  void addCallback(const ros::CallbackInterfacePtr& callback, std::uint64_t owner_id) override
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (open_)
      target_.addCallback(callback, owner_id);
    else
      held_.emplace_back(callback, owner_id);
  }

  void removeByID(std::uint64_t owner_id) override
  {
    std::lock_guard<std::mutex> lock(mutex_);
    std::vector<std::pair<ros::CallbackInterfacePtr, std::uint64_t>> kept;
    for (auto& entry : held_)
      if (entry.second != owner_id)
        kept.push_back(std::move(entry));
    held_.swap(kept);
    target_.removeByID(owner_id);
  }

  /// \brief Forwards the held callbacks in their order; from now on every callback goes straight through.
  void open()
  {
    std::lock_guard<std::mutex> lock(mutex_);
    for (const auto& [callback, owner_id] : held_)
      target_.addCallback(callback, owner_id);
    held_.clear();
    open_ = true;
  }

private:
  ros::CallbackQueueInterface& target_;
  std::mutex mutex_;
  bool open_ = false;
  std::vector<std::pair<ros::CallbackInterfacePtr, std::uint64_t>> held_;
};

template <class Node>
class StageNodelet : public nodelet::Nodelet
{
private:
  void onInit() override
  {
    gate_ = std::make_unique<CallbackGate>(getSTCallbackQueue());
    ros::NodeHandle nh(getNodeHandle()), private_nh(getPrivateNodeHandle());
    nh.setCallbackQueue(gate_.get());
    private_nh.setCallbackQueue(gate_.get());
    try
    {
      node_ = std::make_unique<Node>(nh, private_nh);
    }
    catch (const std::exception& e)
    {
      // As the standalone node's exit: logged, and the manager reports the load as failed.
      NODELET_FATAL("%s: %s", getName().c_str(), e.what());
      throw;
    }
    gate_->open();
  }

  std::unique_ptr<CallbackGate> gate_;  ///< outlives the node (declared first, destroyed last)
  std::unique_ptr<Node> node_;
};
}  // namespace scanhead
