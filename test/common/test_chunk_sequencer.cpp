/// \file test_chunk_sequencer.cpp
/// \brief The chunk sequencer against a per-sample reference: in-order, gaps, overlaps,
/// duplicates, late and reordered chunks, empty chunks, a stream that starts late.
#include <gtest/gtest.h>

#include <cstdint>
#include <random>
#include <set>
#include <vector>

#include "scanhead/common/chunk_sequencer.hpp"

using namespace scanhead;

TEST(ChunkSequencer, InOrderChunksJoinAndCountNothing)
{
  ChunkSequencer s;
  ChunkAdmission a = s.admit(0, 10);
  EXPECT_EQ(a.skip, 0u);
  EXPECT_EQ(a.missing, 0u);
  EXPECT_FALSE(a.broken(false));
  a = s.admit(10, 5);
  EXPECT_FALSE(a.broken(true));
  EXPECT_EQ(s.next(), 15u);
  EXPECT_EQ(s.taken(), 15u);
  EXPECT_EQ(s.missing() + s.repeated() + s.gaps(), 0u);
}

TEST(ChunkSequencer, GapOverlapDuplicateAndLateChunk)
{
  ChunkSequencer s;
  s.admit(0, 10);
  ChunkAdmission a = s.admit(15, 5);  // gap of 5
  EXPECT_EQ(a.missing, 5u);
  EXPECT_TRUE(a.broken(true));
  a = s.admit(18, 4);  // overlap: 18, 19 seen; 20, 21 new and joined
  EXPECT_EQ(a.skip, 2u);
  EXPECT_FALSE(a.broken(true));
  a = s.admit(10, 5);  // the late chunk of the gap: nothing new, nothing broken
  EXPECT_EQ(a.skip, 5u);
  EXPECT_FALSE(a.broken(true));
  a = s.admit(0, 0);  // empty
  EXPECT_EQ(a.skip, 0u);
  EXPECT_EQ(s.taken(), 17u);
  EXPECT_EQ(s.missing(), 5u);
  EXPECT_EQ(s.repeated(), 7u);
  EXPECT_EQ(s.gaps(), 1u);
  EXPECT_EQ(s.overlaps(), 1u);
  EXPECT_EQ(s.lateChunks(), 1u);
}

TEST(ChunkSequencer, StreamStartingLateCountsTheMissingHeadButIsNotBroken)
{
  ChunkSequencer s;
  const ChunkAdmission a = s.admit(7, 3);
  EXPECT_EQ(a.missing, 7u);
  EXPECT_FALSE(a.broken(false));
  EXPECT_EQ(s.gaps(), 1u);
}

TEST(ChunkSequencer, MatchesThePerSampleRuleOnRandomStreams)
{
  // Reference: a sample is taken iff its index exceeds every index taken before; it breaks the
  // stream iff something was taken and it is not the last index + 1.
  std::mt19937_64 rng(20261201);
  for (int trial = 0; trial < 200; ++trial)
  {
    ChunkSequencer s;
    bool started = false;
    std::uint64_t next = 0, taken = 0, repeated = 0, missing = 0;
    for (int c = 0; c < 30; ++c)
    {
      const std::uint64_t first = rng() % 120;
      const std::size_t size = static_cast<std::size_t>(rng() % 9);
      const bool was_started = s.started();
      const ChunkAdmission a = s.admit(first, size);
      std::size_t ref_skip = 0;
      bool ref_broken = false;
      std::uint64_t ref_missing = 0;
      for (std::size_t k = 0; k < size; ++k)
      {
        const std::uint64_t index = first + k;
        if (index < next)
        {
          ++ref_skip;
          ++repeated;
          continue;
        }
        if (index > next)
        {
          ref_broken = started;
          ref_missing = index - next;
          missing += ref_missing;
        }
        started = true;
        next = index + 1;
        ++taken;
      }
      ASSERT_EQ(a.skip, ref_skip);
      ASSERT_EQ(a.broken(was_started), ref_broken);
      ASSERT_EQ(a.missing, ref_missing);
      ASSERT_EQ(s.next(), next);
    }
    EXPECT_EQ(s.taken(), taken);
    EXPECT_EQ(s.repeated(), repeated);
    EXPECT_EQ(s.missing(), missing);
  }
}
