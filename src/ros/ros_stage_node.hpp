/// \file ros_stage_node.hpp
/// \brief The one adapter between a chain stage (common/stage.hpp) and its stream topics: what
/// every stream node (servo, optics, energy) would otherwise write for itself.
///
/// It subscribes the stage's input topics, joins the inputs of each chunk by (job id, first
/// index), resets the stage when a job starts (with the argument the node derives from the job id:
/// e.g. the job and the NC's plan, holding the chunks until they arrive), admits each chunk through
/// a ChunkSequencer (gaps, overlaps and late chunks are counted and logged, chunks with nothing new
/// dropped), runs the stage and hands the output to the node, and tells the node when the job's last
/// sample is in. Memory stays bounded: at most kMaxPendingChunks incomplete chunks are held.
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
#include <string>
#include <tuple>
#include <utility>

#include "scanhead/common/chunk_sequencer.hpp"

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

  /// \brief What the node supplies.
  struct Binding
  {
    /// The stage's reset argument for the job of the chunk \p header (its job_id, period), or
    /// nullopt while what it needs (cam/job, nc/plan) has not arrived: the job's chunks wait.
    std::function<std::optional<JobArgument>(const ChunkHeader& header)> job;
    /// Converts the chunk's messages and runs the stage on them.
    std::function<Output(StageT& stage, const Messages& messages)> process;
    /// The stage's output for the chunk of \p header (the first input's header).
    std::function<void(const Output& output, const ChunkHeader& header)> publish;
    /// The job's last sample is in (optional).
    std::function<void(std::uint32_t job_id)> finished;
  };

  /// \param[in] stage   kept by reference (must outlive this)
  /// \param[in] topics  one input topic per message type, in order
  /// \param[in] name    the node's name in log lines
  StageNodeAdapter(ros::NodeHandle& nh, StageT& stage, const std::array<std::string, kInputs>& topics, Binding binding,
                   std::string name)
    : stage_(stage)
    , binding_(std::move(binding))
    , name_(std::move(name))
  {
    subscribeAll(nh, topics, std::index_sequence_for<InMsgs...>());
  }

  /// \brief Tries the waiting chunks again (call when a job or a plan arrives).
  void retry()
  {
    for (auto it = pending_.begin(); it != pending_.end();)
    {
      const Key key = (it++)->first;  // tryProcess may erase the entry
      tryProcess(key);
    }
  }

  std::uint32_t jobId() const { return job_id_; }
  bool running() const { return running_; }
  const ChunkSequencer& sequence() const { return sequence_; }

private:
  using Key = std::pair<std::uint32_t, std::uint64_t>;  ///< (job id, first index)

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
          std::get<I>(pending_[key]) = std::make_shared<const Msg>(*msg);
          tryProcess(key);
        };
    subscribers_[I] = nh.subscribe<Msg>(topic, 0, callback, ros::VoidConstPtr(), ros::TransportHints().tcpNoDelay());
  }

  static bool complete(const Messages& m)
  {
    return std::apply([](const auto&... p) { return (static_cast<bool>(p) && ...); }, m);
  }

  void tryProcess(const Key& key)
  {
    const auto it = pending_.find(key);
    if (it != pending_.end() && complete(it->second) && startJob(std::get<0>(it->second)->chunk))
    {
      const Messages messages = std::move(it->second);
      pending_.erase(it);
      run(messages);
    }
    while (pending_.size() > kMaxPendingChunks)
    {
      ROS_ERROR("%s: job %u chunk at sample %llu never completed (its job, plan or a stream never came); dropped",
                name_.c_str(), pending_.begin()->first.first,
                static_cast<unsigned long long>(pending_.begin()->first.second));
      pending_.erase(pending_.begin());
    }
  }

  /// Resets the stage at the first chunk of a new job; false while the job's argument is missing.
  bool startJob(const ChunkHeader& header)
  {
    if (running_ && header.job_id == job_id_)
      return true;
    if (!running_ && started_once_ && header.job_id == job_id_)
      return true;  // a late chunk of the finished job: admitted (and dropped) below
    const std::optional<JobArgument> argument = binding_.job(header);
    if (!argument)
      return false;
    if (running_)
      ROS_WARN("%s: job %u interrupted by job %u after %llu samples", name_.c_str(), job_id_, header.job_id,
               static_cast<unsigned long long>(sequence_.next()));
    stage_.reset(*argument);
    job_id_ = header.job_id;
    total_samples_ = header.total_samples;
    sequence_.reset();
    running_ = true;
    started_once_ = true;
    if (header.first_index != 0)
      ROS_ERROR(
          "%s: job %u starts at sample %llu: the first samples were lost upstream (a stage that "
          "connected late?); they are counted as dropped",
          name_.c_str(), job_id_, static_cast<unsigned long long>(header.first_index));
    return true;
  }

  void run(const Messages& messages)
  {
    const ChunkHeader& header = std::get<0>(messages)->chunk;
    const bool started = sequence_.started();
    const std::uint64_t expected = sequence_.next();
    const ChunkAdmission admission = sequence_.admit(header.first_index, chunkSize(messages));
    if (admission.broken(started) || admission.skip > 0)
      ROS_ERROR(
          "%s: job %u: expected sample %llu, got a chunk at %llu (%llu samples missing, %zu already seen: "
          "gap or reordering upstream; counted)",
          name_.c_str(), job_id_, static_cast<unsigned long long>(expected),
          static_cast<unsigned long long>(header.first_index), static_cast<unsigned long long>(admission.missing),
          admission.skip);
    if (!running_ || (admission.skip > 0 && admission.skip == chunkSize(messages)))
      return;  // nothing new
    try
    {
      binding_.publish(binding_.process(stage_, messages), header);
    }
    catch (const std::exception& e)
    {
      ROS_ERROR("%s: job %u chunk at sample %llu: %s", name_.c_str(), job_id_,
                static_cast<unsigned long long>(header.first_index), e.what());
    }
    if (sequence_.next() >= total_samples_)
    {
      running_ = false;
      if (binding_.finished)
        binding_.finished(job_id_);
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

  StageT& stage_;
  Binding binding_;
  std::string name_;
  std::array<ros::Subscriber, kInputs> subscribers_;
  std::map<Key, Messages> pending_;
  ChunkSequencer sequence_;
  std::uint32_t job_id_ = 0;
  std::uint64_t total_samples_ = 0;
  bool running_ = false;
  bool started_once_ = false;
};
}  // namespace scanhead
