#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "scanhead/common/errors.hpp"
#include "scanhead/servo/identification/prbs.hpp"

using namespace scanhead;

// Maximum length: the bit sequence repeats with period exactly 2^n − 1 and no shorter period
// divides it (checked as: the register-driven output first repeats its first n bits + the
// whole period at 2^n − 1). Checked for every supported order.
TEST(Prbs, PeriodIsTwoToTheNMinusOneForEveryOrder)
{
  for (int order = 2; order <= 24; ++order)
  {
    PrbsConfig config;
    config.order = order;
    Prbs prbs(config);
    const std::size_t n = (std::size_t{1} << order) - 1;
    ASSERT_EQ(prbs.periodBits(), n);
    std::vector<char> bits(n);
    long ones = 0;
    for (std::size_t k = 0; k < n; ++k)
    {
      bits[k] = prbs.next() > 0.0;
      ones += bits[k];
    }
    // Balance: 2^(n−1) ones and 2^(n−1) − 1 zeros (exact property of an m-sequence).
    EXPECT_EQ(ones, 1L << (order - 1)) << "order " << order;
    // Next period equals the first (periodic with N).
    bool same = true;
    for (std::size_t k = 0; k < n && same; ++k)
      same = (prbs.next() > 0.0) == static_cast<bool>(bits[k]);
    EXPECT_TRUE(same) << "order " << order;
    // No shorter period: a proper divisor p of N would give bits[k] == bits[k + p]. The
    // balance above already excludes most; check every divisor for the small orders.
    if (order <= 16)
      for (std::size_t p = 1; p < n; ++p)
      {
        if (n % p != 0)
          continue;
        bool periodic = true;
        for (std::size_t k = 0; k + p < n && periodic; ++k)
          periodic = bits[k] == bits[k + p];
        EXPECT_FALSE(periodic) << "order " << order << " has period " << p;
      }
  }
}

// Periodic autocorrelation of ±a: R(0) = a², R(k) = −a²/N for k ≠ 0 (exact, integer arithmetic
// in doubles: tolerance 1e-12 relative).
TEST(Prbs, AutocorrelationIsTwoLevelled)
{
  PrbsConfig config;
  config.order = 10;
  config.amplitude = 2.5;
  Prbs prbs(config);
  const std::size_t n = prbs.periodBits();
  const std::vector<double> x = prbs.take(n);
  const double a2 = config.amplitude * config.amplitude;
  for (std::size_t lag = 0; lag < n; ++lag)
  {
    double r = 0.0;
    for (std::size_t k = 0; k < n; ++k)
      r += x[k] * x[(k + lag) % n];
    r /= static_cast<double>(n);
    const double expected = lag == 0 ? a2 : -a2 / static_cast<double>(n);
    ASSERT_NEAR(r, expected, 1e-12 * a2) << "lag " << lag;
  }
}

// Clock divider: each bit held d samples; the period in samples is d·(2^n − 1); reset restarts.
TEST(Prbs, ClockDividerHoldsBitsAndResetRestarts)
{
  PrbsConfig base;
  base.order = 7;
  PrbsConfig slow = base;
  slow.clock_divider = 3;
  Prbs a(base), b(slow);
  EXPECT_EQ(b.periodSamples(), 3u * 127u);
  const std::vector<double> bits = a.take(127);
  const std::vector<double> held = b.take(3 * 127);
  for (std::size_t k = 0; k < held.size(); ++k)
    ASSERT_EQ(held[k], bits[k / 3]);
  b.reset();
  EXPECT_EQ(b.take(10), std::vector<double>(held.begin(), held.begin() + 10));
}

TEST(Prbs, InvalidConfigNamesTheField)
{
  PrbsConfig c;
  c.order = 25;
  try
  {
    Prbs p(c);
    FAIL();
  }
  catch (const ConfigError& e)
  {
    EXPECT_NE(std::string(e.what()).find("prbs.order must be in [2, 24] (got 25)"), std::string::npos) << e.what();
  }
  c = PrbsConfig();
  c.clock_divider = 0;
  EXPECT_THROW(Prbs{c}, ConfigError);
  c = PrbsConfig();
  c.amplitude = -1.0;
  EXPECT_THROW(Prbs{c}, ConfigError);
}
