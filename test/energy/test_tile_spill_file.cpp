/// \file test_tile_spill_file.cpp
/// \brief The tile spill file: every tile reads back the bytes last written to it, whatever the block cache holds.
#include <gtest/gtest.h>

#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "scanhead/common/errors.hpp"
#include "scanhead/energy/tile_spill_file.hpp"

using scanhead::AlignedFloats;
using scanhead::TileSpillFile;

namespace
{
constexpr std::size_t kFloats = 1024;  // 4 KiB tiles: the smallest that direct I/O allows
constexpr std::size_t kBytes = kFloats * sizeof(float);

/// A tile whose every float tells its tile and version.
AlignedFloats tile(int id, int version)
{
  AlignedFloats t = scanhead::allocateAligned(kFloats);
  for (std::size_t i = 0; i < kFloats; ++i)
    t[i] = static_cast<float>(id * 100000 + version * 10000) + static_cast<float>(i);
  return t;
}

bool readsBack(TileSpillFile& file, std::int64_t offset, int id, int version)
{
  std::vector<float> got(kFloats);
  file.read(offset, got.data());
  const AlignedFloats want = tile(id, version);
  for (std::size_t i = 0; i < kFloats; ++i)
    if (got[i] != want[i])
      return false;
  return true;
}
}  // namespace

// 200 tiles in batches of consecutive and scattered offsets, read back in a random order through one block of 4:
// each read gives the tile's bytes, and the file is read in whole blocks.
TEST(TileSpillFile, EveryTileReadsBackWhatWasWritten)
{
  TileSpillFile file(kBytes, 4, 1, "");
  std::vector<std::int64_t> offsets;
  std::vector<AlignedFloats> data;
  for (int batch = 0; batch < 4; ++batch)
  {
    std::vector<TileSpillFile::Pending> writes;
    for (int k = 0; k < 50; ++k)
    {
      const int id = batch * 50 + k;
      offsets.push_back(file.allocate());
      data.push_back(tile(id, 0));
      writes.push_back({offsets.back(), data.back().get()});
    }
    std::shuffle(writes.begin(), writes.end(), std::mt19937(batch));  // write() sorts them into runs
    file.write(writes);
  }
  EXPECT_EQ(file.bytes(), static_cast<std::int64_t>(200 * kBytes));
  std::vector<int> order(200);
  for (int k = 0; k < 200; ++k)
    order[static_cast<std::size_t>(k)] = k;
  std::shuffle(order.begin(), order.end(), std::mt19937(7));
  for (const int id : order)
    ASSERT_TRUE(readsBack(file, offsets[static_cast<std::size_t>(id)], id, 0)) << "tile " << id;
  EXPECT_LE(file.blockReads(), 200u);
  EXPECT_EQ(file.cacheBytes(), 4 * kBytes + 50 * kBytes);  // the block, and the staging buffer of a batch of 50
  // In order, one read a block of 4.
  const std::uint64_t before = file.blockReads();
  for (int id = 0; id < 200; ++id)
    ASSERT_TRUE(readsBack(file, offsets[static_cast<std::size_t>(id)], id, 0));
  EXPECT_LE(file.blockReads() - before, 51u);
  std::printf("spill file on %s: %s\n", std::getenv("TMPDIR") ? std::getenv("TMPDIR") : "/tmp",
              file.direct() ? "direct I/O" : "page cache");
}

// A tile written again after its block was cached reads the new bytes (the cached copy is updated), and a tile
// appended inside a block that was read while the file was shorter is read again.
TEST(TileSpillFile, CachedBlocksFollowTheWrites)
{
  TileSpillFile file(kBytes, 8, 2, "");
  const std::int64_t a = file.allocate(), b = file.allocate();
  AlignedFloats a0 = tile(1, 0), b0 = tile(2, 0);
  std::vector<TileSpillFile::Pending> writes = {{a, a0.get()}, {b, b0.get()}};
  file.write(writes);
  ASSERT_TRUE(readsBack(file, a, 1, 0));  // caches the block, which ends after b
  AlignedFloats a1 = tile(1, 1);
  writes = {{a, a1.get()}};
  file.write(writes);
  EXPECT_TRUE(readsBack(file, a, 1, 1));
  EXPECT_TRUE(readsBack(file, b, 2, 0));
  const std::int64_t c = file.allocate();  // in the same block, beyond what was read
  AlignedFloats c0 = tile(3, 0);
  writes = {{c, c0.get()}};
  file.write(writes);
  EXPECT_TRUE(readsBack(file, c, 3, 0));
  // clear(): the offsets start again at 0, and the old bytes are never read.
  file.clear();
  EXPECT_EQ(file.bytes(), 0);
  const std::int64_t d = file.allocate();
  EXPECT_EQ(d, 0);
  AlignedFloats d0 = tile(4, 0);
  writes = {{d, d0.get()}};
  file.write(writes);
  EXPECT_TRUE(readsBack(file, d, 4, 0));
}

// Moving the file moves its tiles; the source is left empty.
TEST(TileSpillFile, MovesItsTiles)
{
  TileSpillFile file(kBytes, 2, 1, "");
  const std::int64_t a = file.allocate();
  AlignedFloats a0 = tile(5, 0);
  std::vector<TileSpillFile::Pending> writes = {{a, a0.get()}};
  file.write(writes);
  TileSpillFile moved(std::move(file));
  EXPECT_TRUE(readsBack(moved, a, 5, 0));
  EXPECT_EQ(file.bytes(), 0);  // NOLINT(bugprone-use-after-move): the documented empty state
}

// A folder that cannot hold the file: an InputError naming it and the settings to change, at the first write.
TEST(TileSpillFile, MissingFolderIsAClearError)
{
  TileSpillFile file(kBytes, 4, 1, "/nonexistent/scanhead_spill");
  const std::int64_t a = file.allocate();
  AlignedFloats a0 = tile(6, 0);
  std::vector<TileSpillFile::Pending> writes = {{a, a0.get()}};
  try
  {
    file.write(writes);
    FAIL() << "no error";
  }
  catch (const scanhead::InputError& e)
  {
    const std::string what = e.what();
    EXPECT_NE(what.find("/nonexistent/scanhead_spill"), std::string::npos) << what;
    EXPECT_NE(what.find("energy.spill_dir"), std::string::npos) << what;
  }
}
