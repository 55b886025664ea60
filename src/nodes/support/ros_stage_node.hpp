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
///
/// Once subscribed it announces itself on stream/ready (StageReady: its node name, its process,
/// its input topics), which is what the producers wait for (ros_chunk_outlet.hpp); on destruction
/// it says it went away. It watches for a stalled stream: a job open with no chunk run for
/// `~stall_timeout_s` (default the global `stall_timeout_s`, else 3 s; 0: never), or chunks whose
/// job could not start for that long (its cam/job or nc/plan never came). Silence alone is not a
/// stall: the streams are paced by the last stage's acknowledgements, so a stage that is slow
/// downstream (the energy node finishing a big job) silences every input upstream of it. After
/// `~stall_timeout_s` of silence the nodes publishing the silent inputs, and the stages upstream
/// of them, are pinged (ros_liveness.hpp; at most once a second, in the stall timer, never in a
/// chunk callback): if one is gone it is a stall, named; if all are alive a warning is logged
/// once and the job waits, until `~hang_timeout_s` (default the global `hang_timeout_s`, else
/// 60 s; 0: never) of silence makes it a stall too (a live stage that hangs). A stall is logged
/// with what was seen of each input and why, the job is abandoned (its later chunks are dropped
/// as late, the next job starts clean) and the node's `stalled` hook is called (the energy node
/// writes what it has as an incomplete result).
#pragma once

#include <ros/ros.h>
#include <scanhead/ChunkHeader.h>

#include <array>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <tuple>
#include <utility>

#include "ros_chunk_outlet.hpp"
#include "ros_liveness.hpp"
#include "scanhead/common/stage_driver.hpp"

namespace scanhead
{
/// \brief What a consumer knows of a stalled job.
struct StreamStall
{
  std::uint32_t job_id = 0;
  std::uint64_t next_sample = 0;    ///< the first sample that never came
  std::uint64_t total_samples = 0;  ///< samples the job has
  double waited_s = 0.0;            ///< seconds without a chunk
  std::string streams;              ///< the inputs that stopped, with the last sample seen on each, and why
};

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
    /// The job stalled (optional): called before the job is abandoned (the stage still holds it).
    std::function<void(const StreamStall& stall)> stalled;
    /// A job's chunks were dropped after waiting too long for what the job needs (optional).
    std::function<void(std::uint32_t job_id)> unstartable;
  };

  /// \param[in] private_nh the node's private handle: its name (what producers expect) and parameters
  /// \param[in] stage   kept by reference (must outlive this)
  /// \param[in] topics  one input topic per message type, in order
  /// \param[in] name    the node's name in log lines
  StageNodeAdapter(ros::NodeHandle& nh, const ros::NodeHandle& private_nh, StageT& stage,
                   const std::array<std::string, kInputs>& topics, Binding binding, std::string name)
    : binding_(std::move(binding))
    , name_(std::move(name))
    , driver_(stage, driverHooks())
  {
    stall_timeout_s_ = timeoutParam(nh, private_nh, "stall_timeout_s", 3.0);
    hang_timeout_s_ = timeoutParam(nh, private_nh, "hang_timeout_s", 60.0);
    upstream_ = std::make_unique<UpstreamWatch>(nh);
    subscribeAll(nh, topics, std::index_sequence_for<InMsgs...>());
    // After subscribing: from now on this node gets every chunk published on its topics.
    std::vector<std::string> resolved;
    for (const ros::Subscriber& s : subscribers_)
      resolved.push_back(s.getTopic());
    announcer_ = std::make_unique<ReadyAnnouncer>(nh, private_nh.getNamespace(), resolved);
    if (stall_timeout_s_ > 0.0)
      stall_timer_ = nh.createWallTimer(ros::WallDuration(std::min(0.25, stall_timeout_s_ / 4.0)),
                                        [this](const ros::WallTimerEvent&) { checkStall(); });
  }

  StageNodeAdapter(const StageNodeAdapter&) = delete;
  StageNodeAdapter& operator=(const StageNodeAdapter&) = delete;

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
          if (msg->chunk.job_id == seen_job_[I])
            seen_end_[I] = std::max(seen_end_[I], msg->chunk.first_index + sizeOf(*msg));
          else
          {
            seen_job_[I] = msg->chunk.job_id;
            seen_end_[I] = msg->chunk.first_index + sizeOf(*msg);
          }
          // No copy: the std::shared_ptr keeps the received message alive.
          std::get<I>(pending_[key]) = std::shared_ptr<const Msg>(msg.get(), [msg](const Msg*) {});
          tryProcess(key);
        };
    subscribers_[I] = nh.subscribe<Msg>(topic, 0, callback, ros::VoidConstPtr(), ros::TransportHints().tcpNoDelay());
  }

  /// \brief The stall watch (a wall timer): a job open without progress, or chunks waiting too long.
  void checkStall()
  {
    const ros::WallTime now = ros::WallTime::now();
    const double silent_s = (now - last_progress_).toSec();
    if (driver_.running() && silent_s > stall_timeout_s_ && (now - last_ping_).toSec() >= kPingEvery_s)
    {
      last_ping_ = now;
      StreamStall stall;
      stall.job_id = driver_.jobId();
      stall.next_sample = driver_.sequence().next();
      stall.total_samples = total_samples_;
      stall.waited_s = silent_s;
      std::vector<std::string> silent;
      for (std::size_t i = 0; i < kInputs; ++i)
      {
        const bool this_job = seen_job_[i] == stall.job_id;
        const std::uint64_t end = this_job ? seen_end_[i] : 0;
        if (end > stall.next_sample)
          continue;  // this input is ahead: another one stopped
        if (!stall.streams.empty())
          stall.streams += ", ";
        stall.streams += subscribers_[i].getTopic() + " (last chunk ended at sample " + std::to_string(end) + ")";
        silent.push_back(subscribers_[i].getTopic());
      }
      if (silent.empty())  // every input got ahead of the chunk that never ran: ask about them all
        for (const ros::Subscriber& s : subscribers_)
          silent.push_back(s.getTopic());
      // Off the hot path: only after stall_timeout_s of silence, at most every kPingEvery_s.
      const UpstreamLiveness live = upstream_->check(silent, kPingTimeout_s);
      std::string why;
      if (live.anyDead())
        why = "upstream gone: " + UpstreamLiveness::join(live.dead);
      else if (hang_timeout_s_ > 0.0 && silent_s > hang_timeout_s_)
        why = "hung: " + UpstreamLiveness::join(live.unanswered.empty() ? live.alive : live.unanswered) +
              (live.unanswered.empty() ? " alive" : " not answering") + " but silent for more than ~hang_timeout_s " +
              seconds(hang_timeout_s_);
      if (why.empty())
      {
        if (!waiting_warned_ && live.unanswered.empty())
          ROS_WARN(
              "%s: job %u waiting for %s: %s alive but silent for %.1f s; a slower stage downstream holds the flow "
              "(a stall after ~hang_timeout_s %.1f s)",
              name_.c_str(), stall.job_id, UpstreamLiveness::join(silent).c_str(),
              UpstreamLiveness::join(live.alive).c_str(), silent_s, hang_timeout_s_);
        else if (!waiting_warned_)
          ROS_WARN(
              "%s: job %u waiting for %s, silent for %.1f s: %s not answering (stopped or busy), %s alive (a stall "
              "after ~hang_timeout_s %.1f s)",
              name_.c_str(), stall.job_id, UpstreamLiveness::join(silent).c_str(), silent_s,
              UpstreamLiveness::join(live.unanswered).c_str(), UpstreamLiveness::join(live.alive).c_str(),
              hang_timeout_s_);
        waiting_warned_ = true;
      }
      else
      {
        stall.streams += "; " + why;
        ROS_ERROR(
            "%s: job %u stalled: no chunk for %.1f s (~stall_timeout_s %.1f); sample %llu of %llu never came "
            "from %s; the job is abandoned",
            name_.c_str(), stall.job_id, stall.waited_s, stall_timeout_s_,
            static_cast<unsigned long long>(stall.next_sample), static_cast<unsigned long long>(stall.total_samples),
            stall.streams.c_str());
        if (binding_.stalled)
          binding_.stalled(stall);
        driver_.abandon();
        dropJob(stall.job_id);
        waiting_warned_ = false;
      }
    }
    for (auto it = waiting_since_.begin(); it != waiting_since_.end();)
    {
      const std::uint32_t job_id = it->first;
      const double waited = (now - it->second).toSec();
      ++it;
      if (waited > stall_timeout_s_)
      {
        ROS_ERROR(
            "%s: the chunks of job %u waited %.1f s (~stall_timeout_s) for what their job needs (cam/job, "
            "nc/plan), which never came: dropped",
            name_.c_str(), job_id, waited);
        dropJob(job_id);
        if (binding_.unstartable)
          binding_.unstartable(job_id);
      }
    }
  }

  /// \brief Forgets the held chunks of \p job_id.
  void dropJob(std::uint32_t job_id)
  {
    for (auto it = pending_.begin(); it != pending_.end();)
      it = it->first.first == job_id ? pending_.erase(it) : std::next(it);
    waiting_since_.erase(job_id);
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
      if (verdict == ChunkVerdict::Wait && waiting_since_.emplace(header.job_id, ros::WallTime::now()).second)
        ROS_WARN("%s: the chunks of job %u wait for what their job needs (cam/job, nc/plan)", name_.c_str(),
                 header.job_id);
      if (verdict != ChunkVerdict::Wait)
      {
        waiting_since_.erase(header.job_id);
        const Messages messages = std::move(it->second);
        pending_.erase(it);
        if (verdict == ChunkVerdict::Run)
        {
          last_progress_ = ros::WallTime::now();
          if (waiting_warned_)
          {
            ROS_INFO("%s: job %u resumed", name_.c_str(), header.job_id);
            waiting_warned_ = false;
          }
          total_samples_ = header.total_samples;
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
  template <class Msg>
  static auto sizeOf(const Msg& msg) -> decltype(msg.position.size())
  {
    return msg.position.size() / 2;  // x, y of each sample
  }

  using FirstMsg = std::tuple_element_t<0, std::tuple<InMsgs...>>;
  Binding binding_;
  std::string name_;
  StageDriver<StageT> driver_;
  std::array<ros::Subscriber, kInputs> subscribers_;
  std::map<Key, Messages> pending_;
  std::map<std::uint32_t, ros::WallTime> waiting_since_;  ///< jobs whose chunks wait for their job to start
  std::unique_ptr<ReadyAnnouncer> announcer_;             ///< after subscribers_: withdrawn before they go
  static constexpr double kPingEvery_s = 1.0;             ///< liveness checks while a job is silent
  static constexpr double kPingTimeout_s = 0.5;           ///< per node: a stopped process never answers
  static std::string seconds(double s)
  {
    char text[32];
    std::snprintf(text, sizeof(text), "%.1f s", s);
    return text;
  }
  double stall_timeout_s_ = 3.0, hang_timeout_s_ = 60.0;
  std::unique_ptr<UpstreamWatch> upstream_;  ///< who publishes the inputs, and are they alive
  bool waiting_warned_ = false;              ///< the running job's silence was reported (alive upstream)
  ros::WallTime last_ping_;                  ///< the last liveness check
  ros::WallTimer stall_timer_;
  ros::WallTime last_progress_;                    ///< when the running job last ran a chunk
  std::uint64_t total_samples_ = 0;                ///< of the running job
  std::array<std::uint32_t, kInputs> seen_job_{};  ///< per input: the job of the last chunk received
  std::array<std::uint64_t, kInputs> seen_end_{};  ///< per input: the end of the furthest chunk of that job
  std::shared_ptr<const FirstMsg> current_;        ///< the first input of the chunk being run (its header)
};
}  // namespace scanhead
