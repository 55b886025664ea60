/// \file test_number_text.cpp
/// \brief The number formatter (number_text.hpp) writes the characters of the printf format or
/// stream setting each function names, so the local formatters it replaced print unchanged:
/// every function against its reference over fixed edge values and a seeded sweep of bit patterns.
#include <gtest/gtest.h>

#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "scanhead/common/number_text.hpp"
#include "scanhead/common/random.hpp"

namespace scanhead
{
namespace
{
/// Edge values plus 2000 doubles from random bit patterns (seed 7), any exponent.
std::vector<double> probes()
{
  std::vector<double> v = {0.0,
                           -0.0,
                           0.1,
                           -0.8,
                           100.0,
                           1000.0,
                           1e12,
                           1e-7,
                           123456.5,
                           2.5,
                           -0.004,
                           1e22,
                           1e300,
                           -1e300,
                           5e-324,
                           1.0 / 3.0,
                           std::numeric_limits<double>::max(),
                           std::numeric_limits<double>::lowest(),
                           std::numeric_limits<double>::min(),
                           std::numeric_limits<double>::infinity(),
                           -std::numeric_limits<double>::infinity(),
                           std::numeric_limits<double>::quiet_NaN()};
  SplitMix64 g(7);
  for (int k = 0; k < 2000; ++k)
  {
    const std::uint64_t bits = g.next();
    double x = 0.0;
    std::memcpy(&x, &bits, sizeof x);
    v.push_back(x);
    v.push_back(static_cast<double>(static_cast<std::int64_t>(bits >> 40)) * 1e-3);  // plain decimals
  }
  return v;
}

std::string streamed(double v, int precision)
{
  std::ostringstream s;
  s.precision(precision);
  s << v;
  return s.str();
}

std::string printedF(double v, int decimals)
{
  std::vector<char> buffer(400);
  std::snprintf(buffer.data(), buffer.size(), "%.*f", decimals, v);
  return buffer.data();
}

/// The shortest "%.<n>g" loop as the replaced helpers wrote it (n from \p first to 17).
std::string shortestLoop(double v, int first)
{
  char buffer[40];
  for (int digits = first; digits <= 17; ++digits)
  {
    std::snprintf(buffer, sizeof buffer, "%.*g", digits, v);
    if (std::strtod(buffer, nullptr) == v)
      break;
  }
  return buffer;
}

TEST(NumberFormatting, SignificantTextIsTheStreamWithThatPrecision)
{
  for (const double v : probes())
  {
    for (const int digits : {4, 6, 9, 12, 17})
      ASSERT_EQ(significantText(v, digits), streamed(v, digits)) << v << " at " << digits << " digits";
    ASSERT_EQ(sixDigitText(v), significantText(v, 6));
    ASSERT_EQ(sixDigitText(v), [&] {
      std::ostringstream s;
      s << v;
      return s.str();
    }());
    ASSERT_EQ(fullPrecisionText(v), significantText(v, 17));
  }
  EXPECT_EQ(significantText(0.1, 12), "0.1");
  EXPECT_EQ(significantText(1e12, 9), "1e+12");
}

TEST(NumberFormatting, FixedTextIsPercentF)
{
  for (const double v : probes())
    for (const int decimals : {0, 2, 6})
      ASSERT_EQ(fixedText(v, decimals), printedF(v, decimals)) << v;
  EXPECT_EQ(fixedText(-0.004, 2), "-0.00");
  EXPECT_EQ(fixedText(1e300, 2).size(), 304u);  // no truncation: 301 digits, the point, 2 decimals
}

TEST(NumberFormatting, ShortestTextStartsAtItsMinimumDigits)
{
  for (const double v : probes())
  {
    ASSERT_EQ(shortestText(v), shortestLoop(v, 1)) << v;
    ASSERT_EQ(shortestText(v, 10), shortestLoop(v, 10)) << v;
    ASSERT_EQ(shortestText(v, 15), shortestLoop(v, 15)) << v;
    if (std::isfinite(v))
    {
      ASSERT_EQ(std::strtod(shortestText(v, 10).c_str(), nullptr), v);
    }
  }
  EXPECT_EQ(shortestText(100.0), "1e+02");
  EXPECT_EQ(shortestText(100.0, 3), "100");
  EXPECT_EQ(shortestText(-0.8, 15), "-0.8");
  EXPECT_EQ(shortestText(1e12, 10), "1e+12");
  EXPECT_EQ(shortestText(1e12, 15), "1000000000000");
}

TEST(NumberFormatting, ToCharsTextIsStdToChars)
{
  for (const double v : probes())
  {
    char buffer[64];
    const std::to_chars_result r = std::to_chars(buffer, buffer + sizeof buffer, v);
    ASSERT_EQ(toCharsText(v), std::string(buffer, r.ptr)) << v;
  }
  EXPECT_EQ(toCharsText(100.0), "100");
  EXPECT_EQ(toCharsText(1e-7), "1e-07");
}
}  // namespace
}  // namespace scanhead
