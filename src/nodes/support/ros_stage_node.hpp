/// \file ros_stage_node.hpp
/// \brief The one adapter between a chain stage (common/stage.hpp) and its stream topics: what
/// every stream node (servo, optics, energy) would otherwise write for itself.
///
/// It subscribes the stage's input topics, joins the inputs of each chunk by (job id, first
/// index) without copying them, and hands each complete chunk to a StageDriver
/// (common/stage_driver.hpp: which job a chunk starts or belongs to, sequencing, errors, the job's
/// end); the chunks of a job that cannot start yet (its cam/job or nc/plan not here) wait, logged
/// once. Memory stays bounded: at most kMaxPendingChunks incomplete or waiting chunks are held.
/// A node is left with its parameters, its message conversions and its own extra outputs.
#pragma once

#include <ros/ros.h>
#include <scanhead/ChunkHeader.h>

#include <array>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <tuple>
#include <utility>

#include "ros_chunk_outlet.hpp"
#include "scanhead/common/stage_driver.hpp"

namespace scanhead
{
template <class StageT, class... InMsgs>
class StageNodeAdapter
{
public:
  using Messages = std::tuple<std::shared_ptr<const InMsgs>...>;
  using JobArgument = typename StageT::JobType;
  using Output = typename StageT::OutputType;
  static constexpr std::size_t kInputs = sizeof...(InMsgs);
  static constexpr std::size_t kMaxPendingChunks = 4096;

  /// \brief What the node supplies (see StageDriver::Hooks for when each is called).
  struct Binding
  {
    /// The stage's reset argument for the chunk's job; nullopt while what it needs (cam/job,
    /// nc/plan) has not arrived: the job's chunks wait. Throws if the job cannot run.
    std::function<std::optional<JobArgument>(const ChunkInfo& chunk)> job;
    /// Converts the chunk's messages and runs the stage on them.
    std::function<Output(StageT& stage, const Messages& messages)> process;
    /// The stage's output for the chunk of \p header (the first input's header; optional).
    std::function<void(const Output& output, const ChunkHeader& header)> publish;
    /// After every chunk of the current job, processed or not (optional; the energy node acks here).
    std::function<void(const ChunkInfo& chunk)> consumed;
    /// The job's last sample is in (optional); \p ok false if it failed or a chunk threw.
    std::function<void(std::uint32_t job_id, bool ok)> finished;
  };

  /// \param[in] stage   kept by reference (must outlive this)
  /// \param[in] topics  one input topic per message type, in order
  /// \param[in] name    the node's name in log lines
  StageNodeAdapter(ros::NodeHandle& nh, StageT& stage, const std::array<std::string, kInputs>& topics, Binding binding,
                   std::string name)
    : binding_(std::move(binding))
    , name_(std::move(name))
    , driver_(stage, driverHooks())
  {
    subscribeAll(nh, topics, std::index_sequence_for<InMsgs...>());
  }

  /// \brief Offers the waiting chunks again (call when a job or a plan arrives), in stream order.
  void retry()
  {
    for (auto it = pending_.begin(); it != pending_.end();)
    {
      const Key key = (it++)->first;  // tryProcess may erase the entry
      tryProcess(key);
    }
  }

  const StageDriver<StageT>& driver() const { return driver_; }

private:
  using Key = std::pair<std::uint32_t, std::uint64_t>;  ///< (job id, first index)

  typename StageDriver<StageT>::Hooks driverHooks()
  {
    typename StageDriver<StageT>::Hooks hooks;
    hooks.job = binding_.job;
    hooks.publish = [this](const Output& output, const ChunkInfo&) {
      if (binding_.publish)
        binding_.publish(output, current_->chunk);
    };
    hooks.consumed = binding_.consumed;
    hooks.finished = binding_.finished;
    hooks.error = [this](const std::string& m) { ROS_ERROR("%s: %s", name_.c_str(), m.c_str()); };
    hooks.warn = [this](const std::string& m) { ROS_WARN("%s: %s", name_.c_str(), m.c_str()); };
    return hooks;
  }

  template <std::size_t... I>
  void subscribeAll(ros::NodeHandle& nh, const std::array<std::string, kInputs>& topics, std::index_sequence<I...>)
  {
    (subscribeOne<I>(nh, topics[I]), ...);
  }

  template <std::size_t I>
  void subscribeOne(ros::NodeHandle& nh, const std::string& topic)
  {
    using Msg = std::tuple_element_t<I, std::tuple<InMsgs...>>;
    const boost::function<void(const boost::shared_ptr<const Msg>&)> callback =
        [this](const boost::shared_ptr<const Msg>& msg) {
          const Key key{msg->chunk.job_id, msg->chunk.first_index};
          // No copy: the std::shared_ptr keeps the received message alive.
          std::get<I>(pending_[key]) = std::shared_ptr<const Msg>(msg.get(), [msg](const Msg*) {});
          tryProcess(key);
        };
    subscribers_[I] = nh.subscribe<Msg>(topic, 0, callback, ros::VoidConstPtr(), ros::TransportHints().tcpNoDelay());
    // After subscribing: its producer in this process counts this stage from now on (ChunkOutlet).
    consumers_[I] = std::make_unique<InProcessConsumer>(subscribers_[I].getTopic());
  }

  static bool complete(const Messages& m)
  {
    return std::apply([](const auto&... p) { return (static_cast<bool>(p) && ...); }, m);
  }

  void tryProcess(const Key& key)
  {
    const auto it = pending_.find(key);
    if (it != pending_.end() && complete(it->second))
    {
      const ChunkHeader& header = std::get<0>(it->second)->chunk;
      const ChunkInfo chunk{header.job_id, header.first_index, chunkSize(it->second), header.period,
                            header.total_samples};
      const ChunkVerdict verdict = driver_.offer(chunk);
      if (verdict == ChunkVerdict::Wait && waiting_logged_.insert(header.job_id).second)
        ROS_WARN("%s: the chunks of job %u wait for what their job needs (cam/job, nc/plan)", name_.c_str(),
                 header.job_id);
      if (verdict != ChunkVerdict::Wait)
      {
        const Messages messages = std::move(it->second);
        pending_.erase(it);
        if (verdict == ChunkVerdict::Run)
        {
          current_ = std::get<0>(messages);
          driver_.run(chunk, [&](StageT& stage) { return binding_.process(stage, messages); });
          current_.reset();
        }
      }
    }
    while (pending_.size() > kMaxPendingChunks)
    {
      ROS_ERROR("%s: job %u chunk at sample %llu never completed (its job, plan or a stream never came); dropped",
                name_.c_str(), pending_.begin()->first.first,
                static_cast<unsigned long long>(pending_.begin()->first.second));
      pending_.erase(pending_.begin());
    }
  }

  static std::size_t chunkSize(const Messages& m) { return sizeOf(*std::get<0>(m)); }
  template <class Msg>
  static auto sizeOf(const Msg& msg) -> decltype(msg.trajectory.points.size())
  {
    return msg.trajectory.points.size();
  }
  template <class Msg>
  static auto sizeOf(const Msg& msg) -> decltype(msg.power.size())
  {
    return msg.power.size();
  }

  using FirstMsg = std::tuple_element_t<0, std::tuple<InMsgs...>>;
  Binding binding_;
  std::string name_;
  StageDriver<StageT> driver_;
  std::array<ros::Subscriber, kInputs> subscribers_;
  std::array<std::unique_ptr<InProcessConsumer>, kInputs> consumers_;  ///< after subscribers_: destroyed first
  std::map<Key, Messages> pending_;
  std::set<std::uint32_t> waiting_logged_;   ///< jobs whose waiting was logged (once each)
  std::shared_ptr<const FirstMsg> current_;  ///< the first input of the chunk being run (its header)
};
}  // namespace scanhead
