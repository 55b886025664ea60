/// \file tiled_energy_map.cpp
/// \brief Sparse tiled energy map with a bounded cache and a spill file.
#include "scanhead/energy/tiled_energy_map.hpp"

#include <malloc.h>
#include <algorithm>
#include <cmath>
#include <cstring>
#include <sstream>

#include "region_block_means.hpp"
#include "scanhead/common/errors.hpp"

namespace scanhead
{
namespace
{
constexpr std::int64_t kTilePixels = static_cast<std::int64_t>(TiledEnergyMap::kTileSide) * TiledEnergyMap::kTileSide;
constexpr std::size_t kMinResidentTiles = 16;
constexpr std::size_t kMaxBlockTiles = 64;  // 1 MiB blocks: a direct read at ~1 GB/s
constexpr std::size_t kMaxBlocks = 32;
constexpr std::size_t kSlabTiles = 16;  // tile buffers allocated 16 at a time (256 KiB)

/// \brief The spill file's block cache: an eighth of the budget, blocks of up to kMaxBlockTiles tiles.
struct BlockCache
{
  std::size_t block_tiles = 1, blocks = 1;
};
BlockCache blockCacheFor(std::size_t cache_bytes)
{
  constexpr std::size_t tile_bytes = TiledEnergyMap::kTileBytes;
  const std::size_t share = cache_bytes / 8;
  BlockCache c;
  c.block_tiles = std::clamp<std::size_t>(share / tile_bytes, 1, kMaxBlockTiles);
  c.blocks = std::clamp<std::size_t>(share / (c.block_tiles * tile_bytes), 1, kMaxBlocks);
  return c;
}

TileSpillFile spillFileFor(std::size_t cache_bytes, std::string dir)
{
  const BlockCache c = blockCacheFor(cache_bytes);
  return TileSpillFile(TiledEnergyMap::kTileBytes, c.block_tiles, c.blocks, std::move(dir));
}
}  // namespace

TiledEnergyMap::TiledEnergyMap(const Eigen::Vector2d& min_corner, const Eigen::Vector2d& max_corner, double pixel_m,
                               std::size_t cache_bytes, std::string spill_dir)
  : origin_(min_corner)
  , pixel_(pixel_m)
  , spill_(spillFileFor(cache_bytes, std::move(spill_dir)))
{
  checkMapGeometry(min_corner, max_corner, pixel_m);
  const double extent = std::max(max_corner.x() - min_corner.x(), max_corner.y() - min_corner.y());
  if (extent / pixel_m > 1e9)
  {
    std::ostringstream msg;
    msg << "energy.pixel_m = " << pixel_m << " m is too fine for a " << extent << " m map (over 1e9 pixels a side)";
    throw ConfigError(msg.str());
  }
  width_ = static_cast<std::int64_t>(pixelsAcross(max_corner.x() - min_corner.x(), pixel_m));
  height_ = static_cast<std::int64_t>(pixelsAcross(max_corner.y() - min_corner.y(), pixel_m));
  tiles_x_ = (width_ + kTileSide - 1) / kTileSide;
  tiles_y_ = (height_ + kTileSide - 1) / kTileSide;
  if (static_cast<double>(tiles_x_) * static_cast<double>(tiles_y_) > 2147483647.0)
  {
    std::ostringstream msg;
    msg << "energy.pixel_m = " << pixel_m << " m gives " << tiles_x_ << " x " << tiles_y_
        << " tiles (limit 2^31): increase energy.pixel_m or reduce the job extent";
    throw ConfigError(msg.str());
  }
  max_resident_ = residentTilesFor(cache_bytes);
  slot_of_tile_.assign(static_cast<std::size_t>(tiles_x_ * tiles_y_), -1);
}

TiledEnergyMap::~TiledEnergyMap() = default;

std::size_t TiledEnergyMap::residentTilesFor(std::size_t cache_bytes)
{
  // Tiles T and the spill file's staging buffer (one eviction batch, T/8) share 7/8 of the budget: 9T/8 = 7/8.
  return std::max(kMinResidentTiles, (cache_bytes - cache_bytes / 8) / 9 * 8 / kTileBytes);
}

std::size_t TiledEnergyMap::stagingBytesFor(std::size_t cache_bytes)
{
  return std::max<std::size_t>(1, residentTilesFor(cache_bytes) / 8) * kTileBytes;
}

std::size_t TiledEnergyMap::blockCacheBytesFor(std::size_t cache_bytes)
{
  const BlockCache c = blockCacheFor(cache_bytes);
  return c.blocks * c.block_tiles * kTileBytes;
}

TiledEnergyMap::TiledEnergyMap(TiledEnergyMap&& other) noexcept
{
  *this = std::move(other);
}

TiledEnergyMap& TiledEnergyMap::operator=(TiledEnergyMap&& other) noexcept
{
  if (this != &other)
  {
    origin_ = other.origin_;
    pixel_ = other.pixel_;
    width_ = other.width_;
    height_ = other.height_;
    tiles_x_ = other.tiles_x_;
    tiles_y_ = other.tiles_y_;
    max_resident_ = other.max_resident_;
    slot_of_tile_ = std::move(other.slot_of_tile_);
    slots_ = std::move(other.slots_);
    slot_of_file_tile_ = std::move(other.slot_of_file_tile_);
    spilled_summaries_ = std::move(other.spilled_summaries_);
    buffers_ = std::move(other.buffers_);
    allocated_tiles_ = other.allocated_tiles_;
    free_buffers_ = std::move(other.free_buffers_);
    resident_ = other.resident_;
    peak_resident_ = other.peak_resident_;
    spilled_tiles_ = other.spilled_tiles_;
    clock_ = other.clock_;
    spill_ = std::move(other.spill_);
    summary_valid_ = other.summary_valid_;
    total_ = other.total_;
    peak_ = other.peak_;
    // The source is left an empty map of no pixels (safe to read, nothing to free twice).
    other.width_ = other.height_ = other.tiles_x_ = other.tiles_y_ = 0;
    other.slot_of_tile_.clear();
    other.slots_.clear();
    other.slot_of_file_tile_.clear();
    other.spilled_summaries_.clear();
    other.free_buffers_.clear();
    other.resident_ = other.spilled_tiles_ = 0;
    other.summary_valid_ = false;
    hot_tile_ = -1;
    other.hot_tile_ = -1;
  }
  return *this;
}

void TiledEnergyMap::load(Slot& slot) const
{
  bringBack(slot);
  // Read-ahead: the file block just read holds tiles spilled with this one (neighbours in tile order), which a
  // pass along the track asks for next; they come back now, from the cached block, at most a quarter of the cache
  // (so the eviction that may make room for them never takes this tile, the newest but them).
  const std::int64_t first = spill_.blockStart(slot.file_offset);
  const std::int64_t end = std::min(spill_.bytes(), first + static_cast<std::int64_t>(spill_.blockBytes()));
  std::size_t budget = max_resident_ / 4;
  for (std::int64_t offset = first; offset < end && budget > 0; offset += static_cast<std::int64_t>(kTileBytes))
  {
    Slot& other = slots_[static_cast<std::size_t>(slot_of_file_tile_[fileTileOf(offset)])];
    if (other.data != nullptr || other.file_offset != offset)
      continue;
    other.last_use = ++clock_;
    bringBack(other);
    --budget;
  }
}

void TiledEnergyMap::bringBack(Slot& slot) const
{
  makeRoom();
  slot.data = free_buffers_.back();
  free_buffers_.pop_back();
  ++resident_;
  spill_.read(slot.file_offset, slot.data);
  slot.dirty = false;
}

void TiledEnergyMap::makeRoom() const
{
  hot_tile_ = -1;  // a spill or a new buffer may move the hot tile
  if (resident_ >= max_resident_)
    spillOldest(std::max<std::size_t>(1, resident_ / 8));  // the sort is paid every max/8 misses, not on each
  if (free_buffers_.empty())
  {
    // Slabs of tiles: one aligned allocation a tile would waste up to an alignment (4 KiB) each.
    const std::size_t tiles = std::clamp<std::size_t>(max_resident_ + 1 - allocated_tiles_, 1, kSlabTiles);
    buffers_.push_back(allocateAligned(tiles * static_cast<std::size_t>(kTilePixels)));
    for (std::size_t k = 0; k < tiles; ++k)
      free_buffers_.push_back(buffers_.back().get() + k * static_cast<std::size_t>(kTilePixels));
    allocated_tiles_ += tiles;
  }
  peak_resident_ = std::max(peak_resident_, resident_ + 1);
}

void TiledEnergyMap::spillOldest(std::size_t count) const
{
  hot_tile_ = -1;
  std::vector<Slot*> resident;
  resident.reserve(resident_);
  for (Slot& s : slots_)
    if (s.data != nullptr)
      resident.push_back(&s);
  count = std::min(count, resident.size());
  if (count == 0)
    return;
  std::nth_element(resident.begin(), resident.begin() + static_cast<std::ptrdiff_t>(count - 1), resident.end(),
                   [](const Slot* a, const Slot* b) { return a->last_use < b->last_use; });
  // In tile order: the tiles first spilled now get consecutive offsets in that order, so a later pass in tile
  // order (or along the track) reads the file in long runs.
  std::sort(resident.begin(), resident.begin() + static_cast<std::ptrdiff_t>(count),
            [](const Slot* a, const Slot* b) { return a->tile < b->tile; });
  std::vector<TileSpillFile::Pending> writes;
  writes.reserve(count);
  for (std::size_t k = 0; k < count; ++k)
  {
    Slot& slot = *resident[k];
    if (slot.file_offset < 0)
    {
      slot.file_offset = spill_.allocate();
      ++spilled_tiles_;
      slot_of_file_tile_.push_back(static_cast<std::int32_t>(&slot - slots_.data()));
      spilled_summaries_.emplace_back();
    }
    if (slot.dirty)  // a tile only read since it came back is already in the file, with its summary
    {
      writes.push_back({slot.file_offset, slot.data});
      spilled_summaries_[fileTileOf(slot.file_offset)] = summariseTile(slot.data);
    }
  }
  spill_.write(writes);
  for (std::size_t k = 0; k < count; ++k)
  {
    Slot& slot = *resident[k];
    slot.dirty = false;
    free_buffers_.push_back(slot.data);
    slot.data = nullptr;
    --resident_;
  }
}

void TiledEnergyMap::releaseTiles() const
{
  while (resident_ > 0)
    spillOldest(std::max<std::size_t>(1, max_resident_ / 8));  // one eviction batch: the staging buffer's size
  spill_.finishWrites();
  std::vector<float*>().swap(free_buffers_);
  std::vector<AlignedFloats>().swap(buffers_);
  allocated_tiles_ = 0;
  // Slabs the allocator took from its heaps (not mapped on their own) go back to the system only when trimmed.
  malloc_trim(0);
}

float* TiledEnergyMap::tileForWrite(std::int64_t tile) const
{
  float* data = residentTile(tile);
  summary_valid_ = false;
  slots_[hot_slot_].dirty = true;
  hot_written_ = true;
  return data;
}

float* TiledEnergyMap::residentTile(std::int64_t tile) const
{
  if (tile == hot_tile_)
    return hot_data_;
  std::int32_t& index = slot_of_tile_[static_cast<std::size_t>(tile)];
  if (index < 0)
  {
    makeRoom();
    Slot slot;
    slot.tile = tile;
    slot.data = free_buffers_.back();
    free_buffers_.pop_back();
    std::fill(slot.data, slot.data + kTilePixels, 0.0f);
    ++resident_;
    index = static_cast<std::int32_t>(slots_.size());
    slots_.push_back(slot);
  }
  Slot& slot = slots_[static_cast<std::size_t>(index)];
  slot.last_use = ++clock_;
  if (slot.data == nullptr)
    load(slot);
  hot_tile_ = tile;
  hot_slot_ = static_cast<std::size_t>(index);
  hot_data_ = slot.data;
  hot_written_ = false;
  return slot.data;
}

const float* TiledEnergyMap::tileForRead(std::int64_t tile, float* scratch) const
{
  const std::int32_t index = slot_of_tile_[static_cast<std::size_t>(tile)];
  if (index < 0)
    return nullptr;
  const Slot& slot = slots_[static_cast<std::size_t>(index)];
  if (slot.data != nullptr)
    return slot.data;
  spill_.read(slot.file_offset, scratch);
  return scratch;
}

float TiledEnergyMap::at(std::int64_t col, std::int64_t row) const
{
  if (col < 0 || row < 0 || col >= width_ || row >= height_)
    return 0.0f;
  const std::int64_t tile = (row / kTileSide) * tiles_x_ + col / kTileSide;
  if (slot_of_tile_[static_cast<std::size_t>(tile)] < 0)
    return 0.0f;
  // Through the cache: lookups along a track come back to the same tiles.
  const float* data = residentTile(tile);
  return data[(row % kTileSide) * kTileSide + col % kTileSide];
}

void TiledEnergyMap::addRow(std::int64_t row, std::int64_t col, const float* x, float c, int n)
{
  const std::int64_t tile_row = (row / kTileSide) * tiles_x_;
  const std::int64_t in_row = (row % kTileSide) * kTileSide;
  int done = 0;
  while (done < n)
  {
    const std::int64_t column = col + done;
    const std::int64_t in_col = column % kTileSide;
    const int count = static_cast<int>(std::min<std::int64_t>(n - done, kTileSide - in_col));
    const std::int64_t tile = tile_row + column / kTileSide;
    float* y = (tile == hot_tile_ && hot_written_ ? hot_data_ : tileForWrite(tile)) + in_row + in_col;
    axpyRow(y, x + done, c, count);
    done += count;
  }
}

namespace
{
/// \brief sums[k] += pixel i (i ≡ k mod 8) in double and maxima[k] = max(maxima[k], pixel i) in pixel order, for
/// \p count pixels (a multiple of 8): each lane the operations of a loop over k, so the same bits on every clone.
__attribute__((target_clones("avx2", "default"))) void summariseLanes(const float* data, std::int64_t count,
                                                                      double* sums, float* maxima)
{
  typedef float F4 __attribute__((vector_size(16)));
  typedef float F8 __attribute__((vector_size(32)));
  typedef double D4 __attribute__((vector_size(32)));
  D4 low, high;
  F8 max;
  std::memcpy(&low, sums, sizeof low);
  std::memcpy(&high, sums + 4, sizeof high);
  std::memcpy(&max, maxima, sizeof max);
  for (std::int64_t i = 0; i < count; i += 8)
  {
    F4 a, b;
    F8 v;
    std::memcpy(&a, data + i, sizeof a);
    std::memcpy(&b, data + i + 4, sizeof b);
    std::memcpy(&v, data + i, sizeof v);
    low += __builtin_convertvector(a, D4);
    high += __builtin_convertvector(b, D4);
    max = v > max ? v : max;
  }
  std::memcpy(sums, &low, sizeof low);
  std::memcpy(sums + 4, &high, sizeof high);
  std::memcpy(maxima, &max, sizeof max);
}
}  // namespace

TiledEnergyMap::TileSummary TiledEnergyMap::summariseTile(const float* data)
{
  // Eight partial sums and maxima in a fixed order: deterministic, and the adds overlap.
  TileSummary t;
  float maxima[8] = {};
  summariseLanes(data, kTilePixels, t.sums, maxima);
  for (const float m : maxima)
    t.max = std::max(t.max, m);
  return t;
}

void TiledEnergyMap::summarise() const
{
  // Tile by tile in tile order; a spilled tile by the summary taken when it was written (no read of the file).
  double total = 0.0;
  float peak = 0.0f;
  for (std::int64_t tile = 0; tile < tiles_x_ * tiles_y_; ++tile)
  {
    const std::int32_t index = slot_of_tile_[static_cast<std::size_t>(tile)];
    if (index < 0)
      continue;
    const Slot& slot = slots_[static_cast<std::size_t>(index)];
    const TileSummary t =
        slot.data != nullptr ? summariseTile(slot.data) : spilled_summaries_[fileTileOf(slot.file_offset)];
    for (const double sum : t.sums)
      total += sum;
    peak = std::max(peak, t.max);
  }
  total_ = total * pixel_ * pixel_;
  peak_ = peak;
  summary_valid_ = true;
}

double TiledEnergyMap::totalEnergy() const
{
  if (!summary_valid_)
    summarise();
  return total_;
}

double TiledEnergyMap::peak() const
{
  if (!summary_valid_)
    summarise();
  return peak_;
}

void TiledEnergyMap::clear()
{
  std::fill(slot_of_tile_.begin(), slot_of_tile_.end(), -1);
  for (Slot& s : slots_)
    if (s.data != nullptr)
      free_buffers_.push_back(s.data);
  slots_.clear();
  hot_tile_ = -1;
  resident_ = 0;
  spilled_tiles_ = 0;
  spill_.clear();
  slot_of_file_tile_.clear();
  spilled_summaries_.clear();
  summary_valid_ = false;
}

EnergyMap TiledEnergyMap::region(std::int64_t col0, std::int64_t row0, std::int64_t w, std::int64_t h, int factor) const
{
  return std::move(regions({{col0, row0, w, h, factor}}).front());
}

std::vector<EnergyMap> TiledEnergyMap::regions(const std::vector<RegionRequest>& requests,
                                               const TileVisitor& visit) const
{
  std::vector<RegionBlockMeans> sums;
  sums.reserve(requests.size());
  std::int64_t first_row = tiles_y_, last_row = -1, first_column = tiles_x_, last_column = -1;
  for (const RegionRequest& request : requests)
  {
    sums.emplace_back(*this, request);
    first_row = std::min(first_row, sums.back().firstTileRow());
    last_row = std::max(last_row, sums.back().lastTileRow());
    first_column = std::min(first_column, sums.back().firstTileColumn());
    last_column = std::max(last_column, sums.back().lastTileColumn());
  }
  // Spilled tiles are read into a scratch tile, not into the cache: the pass touches each tile once.
  std::vector<float> scratch(static_cast<std::size_t>(kTilePixels));
  for (std::int64_t tj = first_row; tj <= last_row; ++tj)
  {
    for (std::int64_t ti = first_column; ti <= last_column; ++ti)
    {
      auto covers = [tj, ti](const RegionBlockMeans& region) { return region.coversTile(tj, ti); };
      if (std::none_of(sums.begin(), sums.end(), covers))
        continue;  // between regions: not read
      const float* data = tileForRead(tj * tiles_x_ + ti, scratch.data());
      if (data == nullptr)
        continue;
      if (visit)
        visit(tj * tiles_x_ + ti, data);
      for (RegionBlockMeans& region : sums)
        if (covers(region))
          region.addTile(tj, ti, data);
    }
    for (RegionBlockMeans& region : sums)
      if (region.coversTileRow(tj))
        region.endTileRow(tj);
  }
  std::vector<EnergyMap> out;
  out.reserve(sums.size());
  for (RegionBlockMeans& region : sums)
    out.push_back(region.finish());
  return out;
}

int TiledEnergyMap::blockFactor(std::int64_t w, std::int64_t h, int max_side)
{
  const std::int64_t side = std::max(w, h), m = std::max(1, max_side);
  return static_cast<int>(std::max<std::int64_t>(1, (side + m - 1) / m));
}

std::size_t TiledEnergyMap::peakResidentBytes() const
{
  return peak_resident_ * kTileBytes + spill_.cacheBytes() + slot_of_tile_.size() * sizeof(std::int32_t) +
         slots_.capacity() * sizeof(Slot) + slot_of_file_tile_.capacity() * sizeof(std::int32_t) +
         spilled_summaries_.size() * sizeof(TileSummary);
}
}  // namespace scanhead
