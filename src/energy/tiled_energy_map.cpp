/// \file tiled_energy_map.cpp
/// \brief Sparse tiled energy map with a bounded cache and a spill file.
#include "scanhead/energy/tiled_energy_map.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

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
    observer_ = std::move(other.observer_);
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
  if (observer_)
    observer_(slot.tile, slot.data);
}

void TiledEnergyMap::makeRoom() const
{
  hot_tile_ = -1;  // a spill or a new buffer may move the hot tile
  if (resident_ >= max_resident_)
  {
    // Spill the least recently used eighth at once: the sort is paid every max/8 misses, not on each.
    std::vector<Slot*> resident;
    resident.reserve(resident_);
    for (Slot& s : slots_)
      if (s.data != nullptr)
        resident.push_back(&s);
    const std::size_t count = std::max<std::size_t>(1, resident.size() / 8);
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

TiledEnergyMap::TileSummary TiledEnergyMap::summariseTile(const float* data)
{
  // Eight partial sums and maxima in a fixed order: deterministic, and the adds overlap.
  TileSummary t;
  float maxima[8] = {};
  for (std::int64_t i = 0; i < kTilePixels; i += 8)
    for (int k = 0; k < 8; ++k)
    {
      t.sums[k] += data[i + k];
      maxima[k] = data[i + k] > maxima[k] ? data[i + k] : maxima[k];
    }
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
  const std::int64_t c0 = std::clamp<std::int64_t>(col0, 0, std::max<std::int64_t>(0, width_ - 1));
  const std::int64_t r0 = std::clamp<std::int64_t>(row0, 0, std::max<std::int64_t>(0, height_ - 1));
  const std::int64_t c1 = std::clamp<std::int64_t>(col0 + w, c0 + 1, std::max<std::int64_t>(c0 + 1, width_));
  const std::int64_t r1 = std::clamp<std::int64_t>(row0 + h, r0 + 1, std::max<std::int64_t>(r0 + 1, height_));
  const std::int64_t f = std::max(1, factor);
  const std::int64_t out_w = (c1 - c0 + f - 1) / f, out_h = (r1 - r0 + f - 1) / f;
  const double big = pixel_ * static_cast<double>(f);
  const Eigen::Vector2d lo = origin_ + pixel_ * Eigen::Vector2d(static_cast<double>(c0), static_cast<double>(r0));
  EnergyMap out(lo, lo + big * Eigen::Vector2d(static_cast<double>(out_w), static_cast<double>(out_h)), big);
  // Sums in double per output pixel, tile by tile in tile order (deterministic), then the block mean. Only the output
  // rows a band of tiles reaches are summed at once (a ring of them): the overview of a whole layer needs 100 MB of
  // doubles otherwise. An output row is complete once the band below its last map row is done.
  const std::size_t out_cols = static_cast<std::size_t>(out.width());
  const std::int64_t ring_rows = (kTileSide + f - 1) / f + 1;
  std::vector<double> sum(static_cast<std::size_t>(ring_rows) * out_cols, 0.0);
  auto ringRow = [&](std::int64_t out_row) {
    return sum.data() + static_cast<std::size_t>(out_row % ring_rows) * out_cols;
  };
  const double inv = 1.0 / static_cast<double>(f * f);
  std::int64_t next_out_row = 0;  // the first output row not yet written
  auto writeRowsBefore = [&](std::int64_t end_row) {
    for (; next_out_row < end_row; ++next_out_row)
    {
      double* ring = ringRow(next_out_row);
      float* row = out.row(static_cast<int>(next_out_row));
      for (std::size_t c = 0; c < out_cols; ++c)
      {
        row[c] = static_cast<float>(ring[c] * inv);
        ring[c] = 0.0;
      }
    }
  };
  std::vector<float> scratch(static_cast<std::size_t>(kTilePixels));
  for (std::int64_t tj = r0 / kTileSide; tj <= (r1 - 1) / kTileSide && tj < tiles_y_; ++tj)
  {
    for (std::int64_t ti = c0 / kTileSide; ti <= (c1 - 1) / kTileSide && ti < tiles_x_; ++ti)
    {
      const float* data = tileForRead(tj * tiles_x_ + ti, scratch.data());
      if (data == nullptr)
        continue;
      const std::int64_t rr0 = std::max(r0, tj * kTileSide), rr1 = std::min(r1, (tj + 1) * kTileSide);
      const std::int64_t cc0 = std::max(c0, ti * kTileSide), cc1 = std::min(c1, (ti + 1) * kTileSide);
      for (std::int64_t r = rr0; r < rr1; ++r)
      {
        const float* in = data + (r - tj * kTileSide) * kTileSide - ti * kTileSide;
        double* out_row = ringRow((r - r0) / f);
        // Each output pixel adds its map pixels in column order (the same additions as one += per
        // pixel, so the same bits), without a division per pixel. The whole blocks inside [cc0, cc1)
        // are summed four at a time: four independent chains of adds overlap instead of waiting on one
        // another (full resolution and small factors: ~3× faster; the overview of a layer reads ~1e9
        // pixels).
        const std::int64_t whole0 = c0 + ((cc0 - c0 + f - 1) / f) * f;  // first block starting at or after cc0
        const std::int64_t whole1 = c0 + ((cc1 - c0) / f) * f;          // end of the last block ending by cc1
        auto addPart = [&](std::int64_t from, std::int64_t to) {
          if (from >= to)
            return;
          double& s = out_row[(from - c0) / f];
          for (std::int64_t c = from; c < to; ++c)
            s += in[c];
        };
        // The head (part of a block, or all of [cc0, cc1) when it lies within one block), the whole blocks, the tail.
        const std::int64_t head_end = std::min(cc1, whole0);
        addPart(cc0, head_end);
        const std::int64_t blocks = whole1 > whole0 ? (whole1 - whole0) / f : 0;
        std::int64_t b = 0;
        for (; b + 4 <= blocks; b += 4)
        {
          double* const block_sum = out_row + (whole0 - c0) / f + b;
          double s0 = block_sum[0], s1 = block_sum[1], s2 = block_sum[2], s3 = block_sum[3];
          const float* const p = in + whole0 + b * f;
          for (std::int64_t k = 0; k < f; ++k)
          {
            s0 += p[k];
            s1 += p[f + k];
            s2 += p[2 * f + k];
            s3 += p[3 * f + k];
          }
          block_sum[0] = s0;
          block_sum[1] = s1;
          block_sum[2] = s2;
          block_sum[3] = s3;
        }
        for (; b < blocks; ++b)
          addPart(whole0 + b * f, whole0 + (b + 1) * f);
        addPart(std::max(head_end, whole1), cc1);
      }
    }
    // Output rows whose map rows all lie below the next band: complete.
    writeRowsBefore(std::min<std::int64_t>(out_h, ((tj + 1) * kTileSide - r0) / f));
  }
  writeRowsBefore(out_h);
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
