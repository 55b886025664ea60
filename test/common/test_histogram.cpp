/// \file test_histogram.cpp
/// \brief Histogram: exact counts (edges probed at the double just below each edge), quantiles and
/// shares worked out by hand, under/overflow and non-finite samples, the compensated mean, merge,
/// a seeded random sweep against sorted samples, bad input, and the YAML fragment read back with
/// yaml-cpp bit for bit.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "scanhead/common/errors.hpp"
#include "scanhead/common/histogram.hpp"

using scanhead::Histogram;

TEST(Histogram, CountsAndQuantilesOfBinCentres)
{
  Histogram h(0.0, 10.0, 10);
  for (int i = 0; i < 10; ++i)
    h.add(i + 0.5);
  EXPECT_EQ(h.count(), 10u);
  EXPECT_EQ(h.inRange(), 10u);
  for (int i = 0; i < 10; ++i)
  {
    EXPECT_EQ(h.binCount(i), 1u);
    EXPECT_EQ(h.binEdge(i), i);
  }
  EXPECT_EQ(h.binEdge(10), 10.0);
  EXPECT_EQ(h.min(), 0.5);
  EXPECT_EQ(h.max(), 9.5);
  EXPECT_EQ(h.mean(), 5.0);
  EXPECT_EQ(h.quantile(0.5), 5.0);   // r = 5: the end of bin 4
  EXPECT_EQ(h.quantile(0.25), 2.5);  // r = 2.5: half-way through bin 2
  EXPECT_EQ(h.quantile(0.0), 0.5) << "clamped to min";
  EXPECT_EQ(h.quantile(1.0), 9.5) << "clamped to max";
  EXPECT_EQ(h.fractionBelow(3.0), 0.3);
  EXPECT_EQ(h.fractionBelow(3.5), 0.35);
  EXPECT_EQ(h.fractionBelow(0.2), 0.0);
  EXPECT_EQ(h.fractionBelow(9.5), 0.95) << "linear in bin 9";
  EXPECT_EQ(h.fractionBelow(9.6), 1.0) << "above max: every sample is below";
}

// Hand-computed, uneven counts: 0.5 ×2, 1.5, 3.5 in [0, 4] / 4 bins (bin 2 empty).
TEST(Histogram, QuantilesLinearWithinTheBin)
{
  Histogram h(0.0, 4.0, 4);
  for (double x : {0.5, 1.5, 0.5, 3.5})
    h.add(x);
  EXPECT_EQ(h.quantile(0.5), 1.0);         // r = 2: the end of bin 0
  EXPECT_DOUBLE_EQ(h.quantile(0.6), 1.4);  // r = 2.4: 0.4 into bin 1 (1 sample)
  EXPECT_EQ(h.quantile(0.75), 2.0);        // r = 3: the end of bin 1
  EXPECT_DOUBLE_EQ(h.quantile(0.8), 3.2);  // r = 3.2: the empty bin 2 skipped, 0.2 into bin 3
  EXPECT_EQ(h.quantile(0.1), 0.5) << "r = 0.4: 0.2 in bin 0, clamped to min";
  EXPECT_EQ(h.quantile(0.2), 0.5) << "r = 0.8: 0.4, clamped to min";
  EXPECT_DOUBLE_EQ(h.quantile(0.3), 0.6);  // r = 1.2
  EXPECT_DOUBLE_EQ(h.fractionBelow(1.4), 0.6);
  EXPECT_DOUBLE_EQ(h.fractionBelow(2.5), 0.75) << "the empty bin adds nothing";
  EXPECT_DOUBLE_EQ(h.fractionBelow(3.2), 0.8);
  EXPECT_EQ(h.mean(), 1.5);
}

TEST(Histogram, OutOfRangeAndNonFiniteAreCountedApart)
{
  Histogram h(0.0, 1.0, 1);
  h.add(-3.0);  // underflow
  h.add(0.5);
  h.add(2.0);  // overflow
  h.add(std::numeric_limits<double>::quiet_NaN());
  h.add(std::numeric_limits<double>::infinity());
  h.add(-std::numeric_limits<double>::infinity());
  EXPECT_EQ(h.underflow(), 1u);
  EXPECT_EQ(h.overflow(), 1u);
  EXPECT_EQ(h.inRange(), 1u);
  EXPECT_EQ(h.nonFinite(), 3u);
  EXPECT_EQ(h.count(), 3u) << "finite samples only";
  EXPECT_EQ(h.min(), -3.0);
  EXPECT_EQ(h.max(), 2.0);
  EXPECT_DOUBLE_EQ(h.mean(), -0.5 / 3.0);
  // Underflow spread over [min, lo), overflow over (hi, max].
  EXPECT_EQ(h.quantile(0.0), -3.0);
  EXPECT_DOUBLE_EQ(h.quantile(1.0 / 6.0), -1.5);
  EXPECT_DOUBLE_EQ(h.quantile(0.5), 0.5);
  EXPECT_DOUBLE_EQ(h.quantile(5.0 / 6.0), 1.5);
  EXPECT_EQ(h.quantile(1.0), 2.0);
  EXPECT_DOUBLE_EQ(h.fractionBelow(-1.5), 1.0 / 6.0);
  EXPECT_DOUBLE_EQ(h.fractionBelow(0.0), 1.0 / 3.0) << "lo is an edge: exact";
  EXPECT_DOUBLE_EQ(h.fractionBelow(1.5), 5.0 / 6.0);
  EXPECT_TRUE(std::isnan(h.fractionBelow(std::nan(""))));
  // The range ends: lo into bin 0, hi into the last bin, the doubles beyond them out.
  Histogram e(-1.0, 1.0, 4);
  e.add(-1.0);
  e.add(1.0);
  e.add(std::nextafter(-1.0, -2.0));
  e.add(std::nextafter(1.0, 2.0));
  EXPECT_EQ(e.binCount(0), 1u);
  EXPECT_EQ(e.binCount(3), 1u);
  EXPECT_EQ(e.underflow(), 1u);
  EXPECT_EQ(e.overflow(), 1u);
}

// Edge probes over awkward ranges: binEdge(i) goes into bin i, the double just below it into bin
// i − 1 (the division in the bin lookup may round across an edge; the lookup must not).
TEST(Histogram, EdgesAreExact)
{
  struct Range
  {
    double lo, hi;
    int bins;
  };
  for (const Range r : {Range{0.0, 1.0, 10}, Range{-0.7, 1.3, 7}, Range{1e-6, 3e-6, 13}, Range{-5e-5, 5e-5, 100},
                        Range{0.1, 0.7, 3}, Range{-1e300, 1e300, 999}})
  {
    Histogram h(r.lo, r.hi, r.bins);
    for (int i = 1; i < r.bins; ++i)
    {
      ASSERT_LT(h.binEdge(i - 1), h.binEdge(i));
      h.reset();
      h.add(h.binEdge(i));
      h.add(std::nextafter(h.binEdge(i), -INFINITY));
      ASSERT_EQ(h.binCount(i), 1u) << r.lo << " " << r.hi << " edge " << i;
      ASSERT_EQ(h.binCount(i - 1), 1u) << r.lo << " " << r.hi << " edge " << i;
      EXPECT_EQ(h.fractionBelow(h.binEdge(i)), 0.5);
    }
  }
}

// Catastrophic cancellation: a naive sum of 1e16, 1, −1e16 is 0.
TEST(Histogram, MeanIsCompensated)
{
  Histogram h(-1.0, 1.0, 2);
  for (double x : {1e16, 1.0, -1e16})
    h.add(x);
  EXPECT_EQ(h.mean(), 1.0 / 3.0);
  Histogram a(-1.0, 1.0, 2), b(-1.0, 1.0, 2);
  a.add(1e16);
  a.add(1.0);
  b.add(-1e16);
  a.merge(b);
  EXPECT_EQ(a.mean(), 1.0 / 3.0);
}

// Seeded sweep: merge of two halves = one histogram; quantile within one bin of the sorted-sample
// quantile (the rank-⌈r⌉ sample lies in the bin the quantile is read from); fractionBelow within the
// share of its bin.
TEST(Histogram, RandomSamplesMergeAndQuantiles)
{
  std::mt19937 rng(2024);  // fixed seed
  std::normal_distribution<double> normal(1e-5, 2e-5);
  for (int trial = 0; trial < 20; ++trial)
  {
    const int n = 1 + static_cast<int>(rng() % 3000);
    Histogram whole(-5e-5, 8e-5, 26), first(-5e-5, 8e-5, 26), second(-5e-5, 8e-5, 26);
    std::vector<double> samples;
    for (int k = 0; k < n; ++k)
    {
      const double x = normal(rng);
      samples.push_back(x);
      whole.add(x);
      (k % 3 == 0 ? first : second).add(x);
    }
    first.merge(second);
    EXPECT_EQ(first.binCounts(), whole.binCounts());
    EXPECT_EQ(first.underflow(), whole.underflow());
    EXPECT_EQ(first.overflow(), whole.overflow());
    EXPECT_EQ(first.min(), whole.min());
    EXPECT_EQ(first.max(), whole.max());
    EXPECT_NEAR(first.mean(), whole.mean(), 1e-20);
    std::sort(samples.begin(), samples.end());
    EXPECT_EQ(whole.min(), samples.front());
    EXPECT_EQ(whole.max(), samples.back());
    const double width = whole.binEdge(1) - whole.binEdge(0);
    for (double q : {0.0, 0.01, 0.1, 0.25, 0.5, 0.75, 0.9, 0.99, 0.999, 1.0})
    {
      const double r = q * n;
      const std::size_t rank = std::max<std::size_t>(1, static_cast<std::size_t>(std::ceil(r)));  // 1-based
      const double exact = samples[std::min<std::size_t>(rank, samples.size()) - 1];
      // Outside [lo, hi] the "bin" is [min, lo) or (hi, max]: its width bounds the error there.
      const double bound = exact < whole.lo()   ? whole.lo() - whole.min()
                           : exact > whole.hi() ? whole.max() - whole.hi()
                                                : width;
      EXPECT_LE(std::fabs(whole.quantile(q) - exact), bound * (1 + 1e-12)) << "n " << n << " q " << q;
    }
    for (int i = 0; i <= 26; ++i)
    {
      const double x = whole.binEdge(i);
      const double exact =
          static_cast<double>(std::lower_bound(samples.begin(), samples.end(), x) - samples.begin()) / n;
      EXPECT_NEAR(whole.fractionBelow(x), exact, 1e-15) << "exact at the edges";
    }
  }
}

TEST(Histogram, BadInput)
{
  using scanhead::ConfigError;
  EXPECT_THROW(Histogram(1.0, 1.0, 10), ConfigError);
  EXPECT_THROW(Histogram(2.0, 1.0, 10), ConfigError);
  EXPECT_THROW(Histogram(NAN, 1.0, 10), ConfigError);
  EXPECT_THROW(Histogram(0.0, INFINITY, 10), ConfigError);
  EXPECT_THROW(Histogram(-1e308, 1e308, 10), ConfigError) << "hi - lo overflows";
  EXPECT_THROW(Histogram(0.0, 1.0, 0), ConfigError);
  EXPECT_THROW(Histogram(0.0, 1.0, -3), ConfigError);
  EXPECT_THROW(Histogram(0.0, 1.0, (1 << 24) + 1), ConfigError);
  EXPECT_THROW(Histogram(1e16, 1e16 + 4, 8), ConfigError) << "edges 0.5 apart at 1e16 coincide";
  try
  {
    Histogram(3.0, 2.5, 4);
    FAIL();
  }
  catch (const ConfigError& e)
  {
    EXPECT_NE(std::string(e.what()).find("lo 3, hi 2.5"), std::string::npos) << e.what();
  }
  Histogram h(0.0, 1.0, 4);
  EXPECT_TRUE(std::isnan(h.quantile(0.5)));
  EXPECT_TRUE(std::isnan(h.mean()));
  EXPECT_TRUE(std::isnan(h.min()));
  EXPECT_TRUE(std::isnan(h.fractionBelow(0.5)));
  EXPECT_THROW(h.quantile(-0.1), std::invalid_argument);
  EXPECT_THROW(h.quantile(1.5), std::invalid_argument);
  EXPECT_THROW(h.quantile(NAN), std::invalid_argument);
  EXPECT_THROW(h.binEdge(5), std::out_of_range);
  EXPECT_THROW(h.binCount(4), std::out_of_range);
  EXPECT_THROW(h.merge(Histogram(0.0, 1.0, 5)), std::invalid_argument);
  EXPECT_THROW(h.merge(Histogram(0.0, 2.0, 4)), std::invalid_argument);
  EXPECT_THROW(scanhead::histogramYaml(h, "", 0.0, "m"), std::invalid_argument);
  h.add(0.3);
  h.reset();
  EXPECT_EQ(h.count(), 0u);
  EXPECT_TRUE(std::isnan(h.max()));
}

TEST(Histogram, YamlReadsBackBitExact)
{
  Histogram h(-5e-5, 5e-5, 10);
  std::mt19937 rng(7);  // fixed seed
  std::uniform_real_distribution<double> uni(-6e-5, 6e-5);
  for (int k = 0; k < 500; ++k)
    h.add(uni(rng));
  h.add(NAN);
  const double scale = 1e6;
  const std::string text = scanhead::histogramYaml(h, "    ", scale, "um");
  EXPECT_EQ(text.rfind("    unit: \"um\"\n", 0), 0u) << text;
  const YAML::Node root = YAML::Load("contour_error:\n" + text);
  const YAML::Node y = root["contour_error"];
  ASSERT_TRUE(y.IsMap()) << text;
  EXPECT_EQ(y["unit"].as<std::string>(), "um");
  EXPECT_EQ(y["count"].as<std::uint64_t>(), h.count());
  EXPECT_EQ(y["underflow"].as<std::uint64_t>(), h.underflow());
  EXPECT_EQ(y["overflow"].as<std::uint64_t>(), h.overflow());
  EXPECT_EQ(y["non_finite"].as<std::uint64_t>(), 1u);
  EXPECT_EQ(y["min"].as<double>(), h.min() * scale);
  EXPECT_EQ(y["max"].as<double>(), h.max() * scale);
  EXPECT_EQ(y["mean"].as<double>(), h.mean() * scale);
  EXPECT_EQ(y["quantiles"]["p50"].as<double>(), h.quantile(0.5) * scale);
  EXPECT_EQ(y["quantiles"]["p99"].as<double>(), h.quantile(0.99) * scale);
  EXPECT_EQ(y["lo"].as<double>(), -5e-5 * scale);
  ASSERT_EQ(y["edges"].size(), 11u);
  ASSERT_EQ(y["counts"].size(), 10u);
  for (int i = 0; i <= 10; ++i)
    EXPECT_EQ(y["edges"][i].as<double>(), h.binEdge(i) * scale);
  for (int i = 0; i < 10; ++i)
    EXPECT_EQ(y["counts"][i].as<std::uint64_t>(), h.binCount(i));

  // An empty histogram: NaN as YAML's .nan, still a float; a unit with a quote is escaped.
  const YAML::Node empty = YAML::Load(scanhead::histogramYaml(Histogram(0.0, 1.0, 2), "", 1.0, "a\"b"));
  EXPECT_TRUE(std::isnan(empty["mean"].as<double>()));
  EXPECT_TRUE(std::isnan(empty["quantiles"]["p90"].as<double>()));
  EXPECT_EQ(empty["unit"].as<std::string>(), "a\"b");
  EXPECT_EQ(empty["count"].as<int>(), 0);

  // The literal text of a tiny histogram.
  Histogram t(0.0, 2.0, 2);
  t.add(0.5);
  t.add(1.5);
  EXPECT_EQ(scanhead::histogramYaml(t, "", 1e3, "mrad"),
            "unit: \"mrad\"\n"
            "count: 2  # finite samples\n"
            "underflow: 0  # below lo\n"
            "overflow: 0  # above hi\n"
            "non_finite: 0\n"
            "min: 500\n"
            "max: 1500\n"
            "mean: 1000\n"
            "quantiles: {p50: 1000, p90: 1500, p95: 1500, p99: 1500}\n"
            "lo: 0\n"
            "hi: 2000\n"
            "edges: [0, 1000, 2000]\n"
            "counts: [1, 1]\n");
}
