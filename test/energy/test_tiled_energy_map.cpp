/// \file test_tiled_energy_map.cpp
/// \brief The sparse tiled map: same floats as a dense map whatever spills, bounded memory, exports.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <memory>
#include <random>
#include <vector>

#include "scanhead/common/errors.hpp"
#include "scanhead/energy/energy_accumulator.hpp"
#include "scanhead/energy/track_energy.hpp"

using scanhead::EnergyAccumulator;
using scanhead::EnergyConfig;
using scanhead::EnergyMap;
using scanhead::SpotChunk;
using scanhead::SpotSample;
using scanhead::TiledEnergyMap;

namespace
{
constexpr double kTs = 1e-5;

/// A seeded serpentine over a 6 × 6 mm area at 1 m/s, 200 W: it visits ~400 tiles of 5 µm pixels.
SpotChunk serpentine(unsigned seed)
{
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> jitter(-2e-6, 2e-6);
  SpotChunk c;
  c.period_s = kTs;
  const double step = 1.0 * kTs;  // 10 µm per sample
  for (int line = 0; line < 20; ++line)
  {
    const double y = 0.3e-3 * line;
    for (int k = 0; k <= 600; ++k)
    {
      const double x = (line % 2 == 0 ? k : 600 - k) * step;
      SpotSample s;
      s.actual = Eigen::Vector2d(x + jitter(rng), y + jitter(rng));
      s.power_w = 200.0;
      c.samples.push_back(s);
    }
  }
  return c;
}

EnergyConfig withCache(std::size_t bytes)
{
  EnergyConfig cfg;
  cfg.tile_cache_bytes = bytes;
  return cfg;
}

/// The map of serpentine(seed) in a 1 MiB cache (64 tiles: most of them spilled).
std::unique_ptr<EnergyAccumulator> spilledSerpentine(unsigned seed)
{
  auto acc = std::make_unique<EnergyAccumulator>(withCache(1 << 20), Eigen::Vector2d(-0.3e-3, -0.3e-3),
                                                 Eigen::Vector2d(6.3e-3, 6.0e-3));
  acc->process(serpentine(seed));
  acc->finish();
  return acc;
}
}  // namespace

// Spilling tiles to the file and reading them back changes no float: a 1 MiB cache (64 tiles)
// against one that holds everything, bit for bit.
TEST(TiledEnergyMap, SpillsLeaveTheValuesBitIdentical)
{
  const SpotChunk path = serpentine(3);
  const Eigen::Vector2d lo(-0.3e-3, -0.3e-3), hi(6.3e-3, 6.0e-3);
  EnergyAccumulator small(withCache(1 << 20), lo, hi), large(withCache(1u << 30), lo, hi);
  small.process(path);
  small.finish();
  large.process(path);
  large.finish();
  EXPECT_GT(small.map().tilesSpilled(), 100u);
  EXPECT_EQ(large.map().tilesSpilled(), 0u);
  EXPECT_EQ(small.map().tilesTouched(), large.map().tilesTouched());
  EXPECT_TRUE(small.map().toDense().data() == large.map().toDense().data());
  EXPECT_EQ(small.map().totalEnergy(), large.map().totalEnergy());  // spilled tiles by their summaries
  EXPECT_EQ(small.map().peak(), large.map().peak());
  // Point reads bring spilled tiles back with their neighbours in the file (read-ahead): column by column, against
  // the file's tile order, so tiles are brought back, evicted and brought back again.
  for (std::int64_t c = 0; c < small.map().width(); c += 13)
    for (std::int64_t r = 0; r < small.map().height(); r += 11)
      ASSERT_EQ(small.map().at(c, r), large.map().at(c, r)) << c << ", " << r;
  EXPECT_GT(small.map().spillFile().blockReads(), 10u);
  // Resident memory stays within the cache (64 tiles of 16 KiB) plus the directory and slot table.
  EXPECT_LE(small.map().peakResidentBytes(), (1u << 20) + 64 * 1024);
  // Energy conserved through the spills: deposited = Σ P·Ts within float rounding.
  const double commanded = 200.0 * kTs * (path.samples.size());
  EXPECT_NEAR(small.map().totalEnergy(), commanded, 1e-6 * commanded);
}

// peaksNear (the corner peaks served by the tiles another pass brings back) gives peakNear's values bit for bit:
// discs along and off the serpentine, some off the map, one on no touched tile, on a spilled map while a pass of point
// reads brings tiles back, and with no pass at all.
TEST(TiledEnergyMap, PeaksNearEqualPeakNear)
{
  const std::unique_ptr<EnergyAccumulator> acc = spilledSerpentine(4);
  const TiledEnergyMap& map = acc->map();
  ASSERT_GT(map.tilesSpilled(), 100u);
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> x(-0.5e-3, 6.5e-3), y(-0.5e-3, 6.2e-3), r(0.0, 80e-6);
  std::vector<Eigen::Vector2d> points;
  std::vector<double> radii;
  for (int k = 0; k < 400; ++k)
  {
    points.emplace_back(x(rng), y(rng));
    radii.push_back(r(rng));
  }
  points.emplace_back(-1.0, -1.0);  // far off the map
  radii.push_back(50e-6);
  std::vector<double> expected;
  for (std::size_t k = 0; k < points.size(); ++k)
    expected.push_back(scanhead::peakNear(map, points[k], radii[k]));
  std::size_t brought_back = 0;
  const std::vector<double> during_pass = scanhead::peaksNear(map, points, radii, [&] {
    const std::uint64_t before = map.spillFile().blockReads();
    for (std::int64_t c = 0; c < map.width(); c += 17)
      for (std::int64_t row = 0; row < map.height(); row += 23)
        (void)map.at(c, row);
    brought_back = map.spillFile().blockReads() - before;
  });
  const std::vector<double> no_pass = scanhead::peaksNear(map, points, radii, [] {});
  EXPECT_GT(brought_back, 10u);
  EXPECT_EQ(expected.back(), 0.0);
  std::size_t positive = 0;
  for (std::size_t k = 0; k < points.size(); ++k)
  {
    ASSERT_EQ(during_pass[k], expected[k]) << k;
    ASSERT_EQ(no_pass[k], expected[k]) << k;
    positive += expected[k] > 0.0 ? 1 : 0;
  }
  EXPECT_GT(positive, 200u);
}

// Only visited tiles exist: a whole 350 mm field at 5 µm (4.9e9 pixels) with one spot costs its
// directory (1.2e6 tiles × 4 B) and a few tiles.
TEST(TiledEnergyMap, WholeFieldCostsOnlyWhatTheSpotTouches)
{
  EnergyAccumulator acc(withCache(1u << 28), Eigen::Vector2d(-0.175, -0.175), Eigen::Vector2d(0.175, 0.175));
  EXPECT_EQ(acc.map().width(), 70000);
  SpotChunk c;
  c.period_s = kTs;
  SpotSample s;
  s.actual = Eigen::Vector2d(0.1, -0.05);
  s.power_w = 100.0;
  c.samples.assign(100, s);
  acc.process(c);
  acc.finish();
  EXPECT_LE(acc.map().tilesTouched(), 4u);
  EXPECT_LT(acc.map().peakResidentBytes(), 6u << 20);
  EXPECT_NEAR(acc.map().totalEnergy(), 100 * 100.0 * kTs, 1e-6);
  // The overview conserves the energy: Σ block means × (factor·pixel)².
  const int factor = acc.map().overviewFactor(1000);
  EXPECT_EQ(factor, 70);
  const EnergyMap overview = acc.map().overview(factor);
  EXPECT_EQ(overview.width(), 1000);
  EXPECT_NEAR(overview.totalEnergy(), acc.map().totalEnergy(), 1e-6 * acc.map().totalEnergy());
}

// region() is the matching slice of the dense map, clipped at the edges.
TEST(TiledEnergyMap, RegionIsTheDenseSlice)
{
  const std::unique_ptr<EnergyAccumulator> acc = spilledSerpentine(5);
  const EnergyMap dense = acc->map().toDense();
  const EnergyMap part = acc->map().region(100, 50, 300, 200);
  ASSERT_EQ(part.width(), 300);
  ASSERT_EQ(part.height(), 200);
  EXPECT_NEAR(part.origin().x(), acc->map().origin().x() + 100 * acc->map().pixel(), 1e-15);
  for (int r = 0; r < 200; r += 7)
    for (int c = 0; c < 300; c += 5)
      ASSERT_EQ(part.at(c, r), dense.at(c + 100, r + 50));
  const EnergyMap clipped = acc->map().region(-10, -10, 50, 50);
  EXPECT_EQ(clipped.width(), 40);
  EXPECT_EQ(clipped.at(0, 0), dense.at(0, 0));
}

// region()'s block means equal, bit for bit, the double sums of their pixels taken tile by tile in tile order, then
// row by row and column by column (the order region() documents) over factor²: factors 1 to 30, blocks straddling
// tile edges, partial first and last blocks, clipped edges. (Sums of a few hundred floats in double are exact or
// nearly so, so this catches a pixel missed or added rather than an order changed.)
TEST(TiledEnergyMap, BlockMeansAreThePixelSums)
{
  const std::unique_ptr<EnergyAccumulator> acc = spilledSerpentine(6);
  const TiledEnergyMap& map = acc->map();
  const EnergyMap dense = map.toDense();
  const std::int64_t side = TiledEnergyMap::kTileSide;
  for (int f : {1, 2, 3, 7, 30})
    for (const std::array<std::int64_t, 4>& r :
         {std::array<std::int64_t, 4>{13, 5, 301, 173}, std::array<std::int64_t, 4>{-9, -9, 250, 90},
          std::array<std::int64_t, 4>{0, 0, map.width(), map.height()}})
    {
      const EnergyMap got = map.region(r[0], r[1], r[2], r[3], f);
      const std::int64_t c0 = std::max<std::int64_t>(0, r[0]), r0 = std::max<std::int64_t>(0, r[1]);
      const std::int64_t c1 = std::min(map.width(), r[0] + r[2]), r1 = std::min(map.height(), r[1] + r[3]);
      for (int oy = 0; oy < got.height(); ++oy)
        for (int ox = 0; ox < got.width(); ++ox)
        {
          const std::int64_t bx0 = c0 + ox * f, bx1 = std::min(c1, bx0 + f);
          const std::int64_t by0 = r0 + oy * f, by1 = std::min(r1, by0 + f);
          double sum = 0.0;
          for (std::int64_t tj = by0 / side; tj <= (by1 - 1) / side; ++tj)
            for (std::int64_t ti = bx0 / side; ti <= (bx1 - 1) / side; ++ti)
              for (std::int64_t row = std::max(by0, tj * side); row < std::min(by1, (tj + 1) * side); ++row)
                for (std::int64_t col = std::max(bx0, ti * side); col < std::min(bx1, (ti + 1) * side); ++col)
                  sum += dense.at(static_cast<int>(col), static_cast<int>(row));
          ASSERT_EQ(got.at(ox, oy), static_cast<float>(sum * (1.0 / (f * f))))
              << "factor " << f << ", region at (" << r[0] << ", " << r[1] << "), block (" << ox << ", " << oy << ")";
        }
    }
}

TEST(TiledEnergyMap, BadGeometryIsNamed)
{
  EXPECT_THROW(TiledEnergyMap(Eigen::Vector2d(0, 0), Eigen::Vector2d(1, 1), 0.0, 1 << 20), scanhead::ConfigError);
  EXPECT_THROW(TiledEnergyMap(Eigen::Vector2d(0, 0), Eigen::Vector2d(-1, 1), 1e-6, 1 << 20), scanhead::InputError);
  try
  {
    TiledEnergyMap(Eigen::Vector2d(0, 0), Eigen::Vector2d(1, 1), 1e-12, 1 << 20);
    FAIL() << "a 1e12-pixel-wide map was accepted";
  }
  catch (const scanhead::ConfigError& e)
  {
    EXPECT_NE(std::string(e.what()).find("energy.pixel_m"), std::string::npos) << e.what();
  }
}
