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

// DiscPeakSampler (the corner peaks served by the tiles another pass reads) gives peakNear's values bit for bit: discs
// along and off the serpentine, some off the map, one on no touched tile, on a spilled map, served by a pass over the
// left half of the map (the rest read by finish()), and with no pass at all.
TEST(TiledEnergyMap, DiscPeakSamplerEqualsPeakNear)
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
  scanhead::DiscPeakSampler served(map, points, radii), unserved(map, points, radii);
  std::size_t visited = 0;
  map.regions({{0, 0, map.width() / 2, map.height(), 4}}, [&](std::int64_t tile, const float* data) {
    served.serve(tile, data);
    ++visited;
  });
  const std::vector<double> during_pass = served.finish(map);
  const std::vector<double> no_pass = unserved.finish(map);
  EXPECT_GT(visited, 100u);
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

// TrackEnergySampler (the track's energy served by the tiles another pass reads) gives the statistics of
// trackEnergyProfile on the dense copy of the map bit for bit: the serpentine's own samples plus samples near the map's
// edge and off it, served by a pass over the lower half (the rest read by finish()), and with no pass.
TEST(TiledEnergyMap, TrackEnergySamplerEqualsTheDenseProfile)
{
  const std::unique_ptr<EnergyAccumulator> acc = spilledSerpentine(5);
  const TiledEnergyMap& map = acc->map();
  ASSERT_GT(map.tilesSpilled(), 100u);
  std::vector<SpotSample> spots = serpentine(5).samples;
  SpotSample off;  // a laser-off sample, then a burst along the map's lower edge and beyond it
  spots.push_back(off);
  for (int k = 0; k < 40; ++k)
  {
    SpotSample s;
    s.power_w = 100.0;
    s.actual = Eigen::Vector2d(-0.31e-3 + 0.2e-3 * k, -0.299e-3);
    spots.push_back(s);
  }
  const double exclude = 0.1e-3;
  const scanhead::TrackEnergyProfile dense = scanhead::trackEnergyProfile(map.toDense(), spots, exclude);
  ASSERT_GT(dense.interior_samples, 10000u);
  scanhead::TrackEnergySampler served(map, spots, exclude), unserved(map, spots, exclude);
  map.regions({{0, 0, map.width(), map.height() / 2, 1}},
              [&](std::int64_t tile, const float* data) { served.serve(tile, data); });
  for (const scanhead::TrackEnergyProfile& t : {served.finish(map), unserved.finish(map)})
  {
    EXPECT_EQ(t.interior_samples, dense.interior_samples);
    EXPECT_EQ(t.mean_jpm2, dense.mean_jpm2);
    EXPECT_EQ(t.median_jpm2, dense.median_jpm2);
    EXPECT_EQ(t.peak_jpm2, dense.peak_jpm2);
    EXPECT_EQ(t.min_jpm2, dense.min_jpm2);
    EXPECT_EQ(t.peak_point_m, dense.peak_point_m);
    EXPECT_TRUE(t.energy_jpm2.empty());  // the per-sample arrays are not kept
  }
  EXPECT_GT(dense.mean_jpm2, 0.0);
}

// regions() reads each touched tile once for every region at once, and gives each region's floats bit for bit as
// region() alone: the overview, overlapping crops at full resolution and in blocks, one partly off the map.
TEST(TiledEnergyMap, RegionsInOnePassEqualRegionByRegion)
{
  const std::unique_ptr<EnergyAccumulator> acc = spilledSerpentine(6);
  const TiledEnergyMap& map = acc->map();
  const std::vector<TiledEnergyMap::RegionRequest> requests{{0, 0, map.width(), map.height(), 7},
                                                            {100, 50, 300, 200, 1},
                                                            {250, 120, 400, 333, 3},
                                                            {-40, map.height() - 90, 200, 300, 5}};
  std::vector<int> visits(static_cast<std::size_t>(map.tilesAcross() * ((map.height() + 63) / 64)), 0);
  const std::vector<EnergyMap> together =
      map.regions(requests, [&](std::int64_t tile, const float*) { ++visits[static_cast<std::size_t>(tile)]; });
  ASSERT_EQ(together.size(), requests.size());
  for (std::size_t k = 0; k < requests.size(); ++k)
  {
    const TiledEnergyMap::RegionRequest& r = requests[k];
    const EnergyMap alone = map.region(r.col0, r.row0, r.w, r.h, r.factor);
    EXPECT_EQ(together[k].width(), alone.width()) << k;
    EXPECT_EQ(together[k].origin(), alone.origin()) << k;
    EXPECT_TRUE(together[k].data() == alone.data()) << k;
  }
  std::size_t touched = 0;
  for (const int v : visits)
  {
    EXPECT_LE(v, 1);
    touched += static_cast<std::size_t>(v);
  }
  EXPECT_EQ(touched, map.tilesTouched());  // the overview covers them all: each read once
}

// releaseTiles() sends every resident tile to the file and frees their memory; the values stay, bit for bit, and the
// map keeps accepting deposits (its tiles come back as needed).
TEST(TiledEnergyMap, ReleasedTilesKeepTheirValues)
{
  const Eigen::Vector2d lo(-0.3e-3, -0.3e-3), hi(6.3e-3, 6.0e-3);
  EnergyAccumulator small(withCache(1 << 20), lo, hi), large(withCache(1u << 30), lo, hi);
  small.process(serpentine(7));
  large.process(serpentine(7));
  small.finish();
  const std::vector<float> before = small.map().toDense().data();
  small.map().releaseTiles();
  EXPECT_EQ(small.map().tilesSpilled(), small.map().tilesTouched());  // every tile now in the file
  EXPECT_TRUE(small.map().toDense().data() == before);
  small.process(serpentine(8));
  large.process(serpentine(8));
  small.finish();
  large.finish();
  EXPECT_TRUE(small.map().toDense().data() == large.map().toDense().data());
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
