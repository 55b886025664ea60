/// \file stage_driver.hpp
/// \brief Drives one Stage (stage.hpp) on chunks that arrive as a transport delivers them:
/// from several jobs, late, twice, with gaps, or before what their job needs has arrived.
///
/// What a node would otherwise decide for itself, without ROS, so it is tested with plain gtest:
/// - a chunk of the running job runs; a chunk at sample 0 of another job (or of the finished
///   one: a restarted NC) starts that job; with no job running, a chunk not at sample 0 starts its
///   job too (a stage that connected late: the lost head is logged and counted);
/// - while a job runs, a chunk of another job not at sample 0 is stale (a late chunk of an older
///   job): dropped and logged, so it never resets the stage in the middle of a job;
/// - the job's reset argument comes from a hook: not known yet (the chunk waits), known (the stage
///   is reset), or impossible (the hook or the reset throws: the job fails);
/// - every chunk of the current job is admitted through a ChunkSequencer (gaps, overlaps and late
///   chunks counted and logged) and then reported consumed, even when the stage threw on it or the
///   job failed, so that flow control downstream of it never waits for a chunk that will not come;
/// - the job ends when its last sample is in (finished, with whether it ran without error).
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>

#include "scanhead/common/chunk_sequencer.hpp"

namespace scanhead
{
/// \brief Where a chunk belongs (the fields of a stream's chunk header the driver needs).
struct ChunkInfo
{
  std::uint32_t job_id = 0;
  std::uint64_t first_index = 0;
  std::size_t size = 0;             ///< samples in the chunk
  double period_s = 0.0;            ///< sample period [s]
  std::uint64_t total_samples = 0;  ///< samples the whole job produces
};

/// \brief What to do with an offered chunk.
enum class ChunkVerdict
{
  Run,   ///< give it to run()
  Wait,  ///< keep it: its job cannot start yet (offer it again later)
  Drop,  ///< discard it (stale, or late after its job ended; logged)
};

template <class StageT>
class StageDriver
{
public:
  using JobArgument = typename StageT::JobType;
  using Output = typename StageT::OutputType;

  struct Hooks
  {
    /// The stage's reset argument for the chunk's job; nullopt while unknown (the chunk waits);
    /// throws when the job cannot run (the message is logged, the job fails).
    std::function<std::optional<JobArgument>(const ChunkInfo& chunk)> job;
    /// The stage's output for a chunk (optional).
    std::function<void(const Output& output, const ChunkInfo& chunk)> publish;
    /// After every chunk of the current job, processed or not (optional): e.g. an acknowledgement.
    std::function<void(const ChunkInfo& chunk)> consumed;
    /// The job's last sample is in; \p ok is false if the job failed or a chunk threw (optional).
    std::function<void(std::uint32_t job_id, bool ok)> finished;
    std::function<void(const std::string& message)> error;  ///< log (optional)
    std::function<void(const std::string& message)> warn;   ///< log (optional)
  };

  /// \param[in] stage kept by reference (must outlive this)
  StageDriver(StageT& stage, Hooks hooks)
    : stage_(stage)
    , hooks_(std::move(hooks))
  {
  }

  /// \brief Decides about a complete chunk; starts (resets the stage for) its job when it is due.
  ChunkVerdict offer(const ChunkInfo& chunk)
  {
    if (started_ && chunk.job_id == job_id_ && (running_ || chunk.first_index != 0))
    {
      if (running_)
        return ChunkVerdict::Run;
      ++late_chunks_;  // after its job ended
      return ChunkVerdict::Drop;
    }
    if (running_ && chunk.first_index != 0)
    {
      ++stale_chunks_;
      say(hooks_.warn, "job " + std::to_string(chunk.job_id) + ": chunk at sample " +
                           std::to_string(chunk.first_index) + " while job " + std::to_string(job_id_) +
                           " runs: a late chunk of another job, dropped");
      return ChunkVerdict::Drop;
    }
    return start(chunk);
  }

  /// \brief Runs a chunk offer() said Run to.
  /// \param[in] process runs the stage on the chunk (converts its messages, calls stage.process)
  void run(const ChunkInfo& chunk, const std::function<Output(StageT&)>& process)
  {
    const bool started = sequence_.started();
    const std::uint64_t expected = sequence_.next();
    const ChunkAdmission admission = sequence_.admit(chunk.first_index, chunk.size);
    if (admission.broken(started) || admission.skip > 0)
      say(hooks_.error, "job " + std::to_string(job_id_) + ": expected sample " + std::to_string(expected) +
                            ", got a chunk at " + std::to_string(chunk.first_index) + " (" +
                            std::to_string(admission.missing) + " samples missing, " + std::to_string(admission.skip) +
                            " already seen: a gap or reordering upstream; counted)");
    const bool fresh = admission.skip < chunk.size;
    if (fresh && !failed_)
    {
      try
      {
        const Output output = process(stage_);
        if (hooks_.publish)
          hooks_.publish(output, chunk);
      }
      catch (const std::exception& e)
      {
        chunk_failed_ = true;
        say(hooks_.error, "job " + std::to_string(job_id_) + ": chunk at sample " + std::to_string(chunk.first_index) +
                              ": " + e.what());
      }
    }
    if (hooks_.consumed)
      hooks_.consumed(chunk);
    if (running_ && sequence_.next() >= total_samples_)
    {
      running_ = false;
      if (hooks_.finished)
      {
        try
        {
          hooks_.finished(job_id_, !failed_ && !chunk_failed_);
        }
        catch (const std::exception& e)
        {
          say(hooks_.error, "job " + std::to_string(job_id_) + ": at its end: " + e.what());
        }
      }
    }
  }

  /// \brief Ends the running job without its missing samples (its stream stalled): its later
  /// chunks are dropped as late; a chunk at sample 0 starts a job again.
  void abandon() { running_ = false; }

  std::uint32_t jobId() const { return job_id_; }
  bool running() const { return running_; }
  bool failed() const { return failed_; }
  const ChunkSequencer& sequence() const { return sequence_; }
  std::uint64_t staleChunks() const { return stale_chunks_; }  ///< of other jobs, dropped while a job ran
  std::uint64_t lateChunks() const { return late_chunks_; }    ///< of a job that had ended, dropped

private:
  ChunkVerdict start(const ChunkInfo& chunk)
  {
    std::string failure;
    try
    {
      const std::optional<JobArgument> argument = hooks_.job(chunk);
      if (!argument)
        return ChunkVerdict::Wait;
      if (running_)
        say(hooks_.warn, "job " + std::to_string(job_id_) + " interrupted by job " + std::to_string(chunk.job_id) +
                             " after " + std::to_string(sequence_.next()) + " samples");
      stage_.reset(*argument);
    }
    catch (const std::exception& e)
    {
      failure = e.what();
    }
    job_id_ = chunk.job_id;
    total_samples_ = chunk.total_samples;
    sequence_.reset();
    started_ = true;
    running_ = true;
    failed_ = !failure.empty();
    chunk_failed_ = false;
    if (failed_)
      say(hooks_.error,
          "job " + std::to_string(job_id_) + " cannot run: " + failure + " (its chunks are acknowledged and dropped)");
    else if (chunk.first_index != 0)
      say(hooks_.error, "job " + std::to_string(job_id_) + " starts at sample " + std::to_string(chunk.first_index) +
                            ": the first samples were lost upstream (a stage that connected late?); they are "
                            "counted as dropped");
    return ChunkVerdict::Run;
  }

  static void say(const std::function<void(const std::string&)>& log, const std::string& message)
  {
    if (log)
      log(message);
  }

  StageT& stage_;
  Hooks hooks_;
  ChunkSequencer sequence_;
  std::uint32_t job_id_ = 0;
  std::uint64_t total_samples_ = 0;
  bool started_ = false;       ///< a job was started since construction
  bool running_ = false;       ///< the current job has samples to come
  bool failed_ = false;        ///< the current job could not start
  bool chunk_failed_ = false;  ///< a chunk of the current job threw
  std::uint64_t stale_chunks_ = 0, late_chunks_ = 0;
};
}  // namespace scanhead
