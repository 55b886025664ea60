/// \file test_stage_driver.cpp
/// \brief The stage driver the nodes share, on a fake stage: job starts and restarts, stale and
/// late chunks, jobs that must wait or cannot run, chunks that throw; every chunk of the current
/// job is reported consumed (flow control never waits) and each job ends once.
#include <gtest/gtest.h>

#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "scanhead/common/stage.hpp"
#include "scanhead/common/stage_driver.hpp"

using namespace scanhead;

namespace
{
/// Reset with a job number; process(x) returns 2x, throws on x < 0; resets with a negative job throw.
class FakeStage final : public Stage<int, int, int>
{
public:
  void reset(const int& job) override
  {
    if (job < 0)
      throw std::runtime_error("bad job");
    resets.push_back(job);
  }
  int process(const int& x) override
  {
    if (x < 0)
      throw std::runtime_error("bad chunk");
    return 2 * x;
  }
  int finish() override { return 0; }
  std::vector<int> resets;
};

struct Recorder
{
  std::vector<int> outputs;
  std::vector<std::uint64_t> consumed;  // first_index of each consumed chunk
  std::vector<std::pair<std::uint32_t, bool>> finished;
  std::vector<std::string> errors, warnings;
  bool job_known = true;
  int job_argument = 1;
};

StageDriver<FakeStage>::Hooks hooks(Recorder& r)
{
  StageDriver<FakeStage>::Hooks h;
  h.job = [&r](const ChunkInfo& c) -> std::optional<int> {
    if (!r.job_known)
      return std::nullopt;
    return r.job_argument < 0 ? r.job_argument : static_cast<int>(c.job_id);
  };
  h.publish = [&r](const int& out, const ChunkInfo&) { r.outputs.push_back(out); };
  h.consumed = [&r](const ChunkInfo& c) { r.consumed.push_back(c.first_index); };
  h.finished = [&r](std::uint32_t job, bool ok) { r.finished.emplace_back(job, ok); };
  h.error = [&r](const std::string& m) { r.errors.push_back(m); };
  h.warn = [&r](const std::string& m) { r.warnings.push_back(m); };
  return h;
}

ChunkInfo chunk(std::uint32_t job, std::uint64_t first, std::size_t size = 10, std::uint64_t total = 30)
{
  return ChunkInfo{job, first, size, 1e-5, total};
}

/// Offers and, if told to run, runs a chunk whose value is \p x.
ChunkVerdict feed(StageDriver<FakeStage>& d, const ChunkInfo& c, int x = 1)
{
  const ChunkVerdict v = d.offer(c);
  if (v == ChunkVerdict::Run)
    d.run(c, [x](FakeStage& s) { return s.process(x); });
  return v;
}
}  // namespace

TEST(StageDriver, RunsAJobToItsEndOnce)
{
  FakeStage stage;
  Recorder r;
  StageDriver<FakeStage> d(stage, hooks(r));
  for (std::uint64_t first : {0u, 10u, 20u})
    EXPECT_EQ(feed(d, chunk(1, first), 3), ChunkVerdict::Run);
  EXPECT_EQ(stage.resets, std::vector<int>{1});
  EXPECT_EQ(r.outputs, (std::vector<int>{6, 6, 6}));
  EXPECT_EQ(r.consumed, (std::vector<std::uint64_t>{0, 10, 20}));
  ASSERT_EQ(r.finished.size(), 1u);
  EXPECT_EQ(r.finished[0], std::make_pair(1u, true));
  EXPECT_TRUE(r.errors.empty());
}

TEST(StageDriver, ARestartedJobRunsAgainALateChunkDoesNot)
{
  FakeStage stage;
  Recorder r;
  StageDriver<FakeStage> d(stage, hooks(r));
  for (std::uint64_t first : {0u, 10u, 20u})
    feed(d, chunk(1, first));
  EXPECT_EQ(feed(d, chunk(1, 10)), ChunkVerdict::Drop);  // late, after the end
  EXPECT_EQ(d.lateChunks(), 1u);
  EXPECT_EQ(feed(d, chunk(1, 0)), ChunkVerdict::Run);  // the same id from sample 0: an NC restarted
  EXPECT_EQ(stage.resets, (std::vector<int>{1, 1}));
}

TEST(StageDriver, AStaleChunkOfAnotherJobNeverResetsTheRunningOne)
{
  FakeStage stage;
  Recorder r;
  StageDriver<FakeStage> d(stage, hooks(r));
  feed(d, chunk(2, 0));
  EXPECT_EQ(feed(d, chunk(1, 20)), ChunkVerdict::Drop);
  EXPECT_EQ(d.staleChunks(), 1u);
  EXPECT_EQ(stage.resets, std::vector<int>{2});
  EXPECT_EQ(feed(d, chunk(3, 0)), ChunkVerdict::Run);  // a new job from its start interrupts
  EXPECT_EQ(stage.resets, (std::vector<int>{2, 3}));
  EXPECT_EQ(r.warnings.size(), 2u);  // the stale chunk, the interruption
}

TEST(StageDriver, AJobWaitsForItsArgumentAndALateStageStartsWhereTheStreamIs)
{
  FakeStage stage;
  Recorder r;
  r.job_known = false;
  StageDriver<FakeStage> d(stage, hooks(r));
  EXPECT_EQ(d.offer(chunk(1, 0)), ChunkVerdict::Wait);
  EXPECT_TRUE(stage.resets.empty());
  r.job_known = true;
  EXPECT_EQ(feed(d, chunk(1, 10)), ChunkVerdict::Run);  // connected late: starts at 10, says so
  EXPECT_EQ(r.errors.size(), 1u);
  feed(d, chunk(1, 20));
  ASSERT_EQ(r.finished.size(), 1u);
  EXPECT_EQ(d.sequence().missing(), 10u);  // the lost head is counted
}

TEST(StageDriver, AJobThatCannotRunIsConsumedNotProcessedAndEndsNotOk)
{
  FakeStage stage;
  Recorder r;
  r.job_argument = -1;  // the reset throws
  StageDriver<FakeStage> d(stage, hooks(r));
  for (std::uint64_t first : {0u, 10u, 20u})
    EXPECT_EQ(feed(d, chunk(1, first)), ChunkVerdict::Run);
  EXPECT_TRUE(d.failed());
  EXPECT_TRUE(r.outputs.empty());
  EXPECT_EQ(r.consumed.size(), 3u);
  ASSERT_EQ(r.finished.size(), 1u);
  EXPECT_FALSE(r.finished[0].second);
}

TEST(StageDriver, AChunkThatThrowsIsStillConsumed)
{
  FakeStage stage;
  Recorder r;
  StageDriver<FakeStage> d(stage, hooks(r));
  feed(d, chunk(1, 0), 1);
  feed(d, chunk(1, 10), -1);  // throws
  feed(d, chunk(1, 20), 1);
  EXPECT_EQ(r.outputs, (std::vector<int>{2, 2}));
  EXPECT_EQ(r.consumed.size(), 3u);
  ASSERT_EQ(r.finished.size(), 1u);
  EXPECT_FALSE(r.finished[0].second);
  EXPECT_EQ(r.errors.size(), 1u);
}

TEST(StageDriver, DuplicatesAreCountedAndNotProcessedTwice)
{
  FakeStage stage;
  Recorder r;
  StageDriver<FakeStage> d(stage, hooks(r));
  feed(d, chunk(1, 0));
  feed(d, chunk(1, 0));   // a duplicate: admitted, nothing new
  feed(d, chunk(1, 20));  // a gap of 10
  EXPECT_EQ(r.outputs.size(), 2u);
  EXPECT_EQ(d.sequence().repeated(), 10u);
  EXPECT_EQ(d.sequence().missing(), 10u);
  EXPECT_EQ(r.errors.size(), 2u);
}
