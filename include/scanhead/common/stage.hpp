/// \file stage.hpp
/// \brief The one interface of the chain's stages (CAM, NC, servo, optics, energy): reset for a
/// job, process a chunk into a chunk, finish.
///
/// A stage keeps its state across chunks, and the chunking never changes what it produces (a
/// chunk of 1, 7 or 1000 samples gives the same bits: each stage's tests prove it). The batch
/// chain, the benchmark and the ROS nodes all drive the stages through this interface, so they
/// run the same code in the same order.
#pragma once

namespace scanhead
{
/// \tparam JobInput what the stage needs to know when a job starts (the job, the NC's plan…)
/// \tparam Input    one chunk in (for a source: how much to produce)
/// \tparam Output   one chunk out
/// \tparam Result   what finish() gives (the job's figures, or the last chunk)
template <class JobInput, class Input, class Output, class Result = Output>
class Stage
{
public:
  using JobType = JobInput;
  using InputType = Input;
  using OutputType = Output;
  using ResultType = Result;

  virtual ~Stage() = default;
  /// \brief Forgets the previous job and prepares for \p job.
  virtual void reset(const JobInput& job) = 0;
  /// \brief The output of the next chunk of the job.
  virtual Output process(const Input& input) = 0;
  /// \brief Ends the job (no chunk follows until the next reset()).
  virtual Result finish() = 0;
};
}  // namespace scanhead
