/// \file test_random.cpp
/// \brief The shared generator (random.hpp): splitmix64's published outputs, and its two
/// mappings to doubles at their ends.
#include <gtest/gtest.h>

#include <cstdint>

#include "scanhead/common/random.hpp"

namespace scanhead
{
namespace
{
TEST(Random, Splitmix64IsTheReferenceSequence)
{
  // Vigna's reference splitmix64.c, seed 0: the first two outputs.
  SplitMix64 g(0);
  EXPECT_EQ(g.next(), 0xe220a8397b1dcdafULL);
  EXPECT_EQ(g.next(), 0x6e789e6aa1b965f4ULL);
  // The state is only the seed: two generators with one seed agree, another seed differs.
  SplitMix64 a(12345);
  SplitMix64 b(12345);
  SplitMix64 c(12346);
  for (int k = 0; k < 100; ++k)
  {
    const std::uint64_t x = a.next();
    EXPECT_EQ(x, b.next());
    EXPECT_NE(x, c.next());
  }
}

TEST(Random, UniformsAreTheTop53BitsExactly)
{
  // Seed 0's first output, mapped by hand: top 53 bits × 2^-53, and + 1 for (0, 1].
  SplitMix64 closed_open(0);
  SplitMix64 open_closed(0);
  const double top = static_cast<double>(0xe220a8397b1dcdafULL >> 11);
  EXPECT_EQ(closed_open.uniformClosedOpen(), top / 9007199254740992.0);
  EXPECT_EQ(open_closed.uniformOpenClosed(), (top + 1.0) / 9007199254740992.0);
  // Over many draws: [0, 1) and (0, 1], mean 1/2 (σ of the mean 0.29/√10⁵ < 0.001: ±0.005 is 5σ).
  SplitMix64 g(7);
  double sum = 0.0;
  for (int k = 0; k < 100000; ++k)
  {
    const double u = g.uniformClosedOpen();
    const double v = g.uniformOpenClosed();
    ASSERT_GE(u, 0.0);
    ASSERT_LT(u, 1.0);
    ASSERT_GT(v, 0.0);
    ASSERT_LE(v, 1.0);
    sum += u;
  }
  EXPECT_NEAR(sum / 100000.0, 0.5, 0.005);
}
}  // namespace
}  // namespace scanhead
