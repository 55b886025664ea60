/// \file tiled_energy_map.hpp
/// \brief Sparse energy map of a whole layer: square tiles allocated only where the spot passes,
/// the least recently used ones spilled to a temporary file, so memory stays bounded whatever the
/// job's extent and length (a 350 mm field at 5 µm is 4.9e9 pixels: 20 GB as a dense float image).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "scanhead/energy/energy_map.hpp"
#include "scanhead/energy/tile_spill_file.hpp"

namespace scanhead
{
/// \brief Energy density E [J/m²] at pixel centres origin + (i + 0.5, j + 0.5)·pixel, i < width,
/// j < height; untouched pixels read 0.
///
/// Pixels live in tiles of kTileSide² floats (tile (ti, tj) holds columns [ti·S, ti·S + S) and rows
/// [tj·S, tj·S + S)). A dense directory maps each tile to its slot (4 B per tile: 4.8 MB for a
/// 350 mm field at 5 µm). At most cache_bytes of tiles and spill-file buffers are resident: when the tiles' share
/// (8/9 of 7/8: 7/9 of it) is full, the oldest eighth (by last use) is written to a TileSpillFile in one batch (in the
/// background, from its staging buffer: the rest of the 7/8), in tile order at consecutive offsets, and read back
/// through its block cache (the other 1/8, blocks of up to 64 tiles) when touched again. Values never depend on what
/// was spilled: the same deposits give the same floats, bit for bit. Reading methods are const but may load tiles (the
/// cache is mutable). Move-only (it owns the spill file).
class TiledEnergyMap
{
public:
  static constexpr int kTileSide = 64;  ///< tile side [pixels]: 16 KiB of floats, 0.32 mm at 5 µm
  static constexpr std::size_t kTileBytes = sizeof(float) * kTileSide * kTileSide;

  /// \brief A map covering [min_corner, max_corner] (width = max(1, ceil(extent/pixel)), as EnergyMap).
  /// \param[in] cache_bytes resident tiles and spill-file blocks at most (≥ 16 tiles and one block are always allowed)
  /// \param[in] spill_dir   folder of the spill file; "": $TMPDIR, else /tmp
  /// \throws ConfigError if pixel_m is not > 0 or the tile directory would exceed 2^31 tiles
  /// \throws InputError if the corners are not finite or max < min
  TiledEnergyMap(const Eigen::Vector2d& min_corner, const Eigen::Vector2d& max_corner, double pixel_m,
                 std::size_t cache_bytes, std::string spill_dir = "");
  ~TiledEnergyMap();
  TiledEnergyMap(TiledEnergyMap&& other) noexcept;
  TiledEnergyMap& operator=(TiledEnergyMap&& other) noexcept;
  TiledEnergyMap(const TiledEnergyMap&) = delete;
  TiledEnergyMap& operator=(const TiledEnergyMap&) = delete;

  std::int64_t width() const { return width_; }
  std::int64_t height() const { return height_; }
  double pixel() const { return pixel_; }
  const Eigen::Vector2d& origin() const { return origin_; }

  /// \brief E at pixel (col, row) [J/m²]; 0 outside the map or on an untouched tile.
  float at(std::int64_t col, std::int64_t row) const;
  /// \brief E[row][col + k] += c·x[k], k < n; the span must lie on the map (the accumulator clips).
  void addRow(std::int64_t row, std::int64_t col, const float* x, float c, int n);

  double totalEnergy() const;  ///< Σ E·pixel² [J], summed per tile in tile order (deterministic; cached)
  double peak() const;         ///< max E [J/m²] (cached with the total: one pass over the tiles)
  void clear();                ///< back to no tile at all (the spill file is reused)

  /// \brief A dense copy of the pixels [col0, col0 + w) × [row0, row0 + h) (clipped to the map;
  /// zeros where untouched), averaged over blocks of factor × factor pixels (energy conserved: block
  /// mean E on pixels factor× larger; the last blocks are partial, averaged over the full block
  /// area); its origin is that of pixel (col0, row0).
  /// \throws ConfigError from EnergyMap if the result exceeds 2^31 pixels
  EnergyMap region(std::int64_t col0, std::int64_t row0, std::int64_t w, std::int64_t h, int factor = 1) const;
  /// \brief region()'s arguments.
  struct RegionRequest
  {
    std::int64_t col0 = 0, row0 = 0, w = 0, h = 0;
    int factor = 1;
  };
  /// \brief Shown each touched tile a pass reads: its index (row · tilesAcross() + column) and kTileSide² pixels
  /// (row-major; 0 beyond the map's edge).
  using TileVisitor = std::function<void(std::int64_t, const float*)>;
  /// \brief region() of every request in one pass over the tiles in tile order: each tile is read once however many
  /// regions overlap it, and shown to \p visit (other readers served by the same read of the spill file). Each region
  /// adds its tiles in its own tile order: the same bits as region() one by one.
  std::vector<EnergyMap> regions(const std::vector<RegionRequest>& requests, const TileVisitor& visit = {}) const;
  /// \brief The whole map in blocks of factor × factor pixels (region() of everything).
  EnergyMap overview(int factor) const { return region(0, 0, width_, height_, factor); }
  /// \brief The smallest block factor that brings w × h pixels to at most max_side a side.
  static int blockFactor(std::int64_t w, std::int64_t h, int max_side);
  /// \brief blockFactor of the whole map.
  int overviewFactor(int max_side) const { return blockFactor(width_, height_, max_side); }
  /// \brief The whole map dense (small maps, tests). \throws ConfigError beyond 2^31 pixels
  EnergyMap toDense() const { return region(0, 0, width_, height_); }

  std::size_t tilesTouched() const { return slots_.size(); }
  std::size_t tilesSpilled() const { return spilled_tiles_; }  ///< tiles that were written to the file at least once
  /// \brief Largest memory the tiles, the file's block cache and the directory held [bytes].
  std::size_t peakResidentBytes() const;
  std::size_t spillFileBytes() const { return static_cast<std::size_t>(spill_.bytes()); }
  /// \brief Waits for the spill file's background write (EnergyAccumulator::finish: a failed write is said at the end
  /// of the stream, not at the next read). \throws InputError naming the folder if it failed
  void finishWrites() const { spill_.finishWrites(); }
  const TileSpillFile& spillFile() const { return spill_; }

  /// \brief How a map divides cache_bytes: tiles resident at most (8/9 of 7/8 of it, ≥ 16 tiles); the rest of the 7/8
  /// is the spill file's staging buffer (stagingBytesFor: one eviction batch, an eighth of the tiles).
  static std::size_t residentTilesFor(std::size_t cache_bytes);
  /// \brief The spill file's staging buffer at most (the largest eviction batch) [bytes].
  static std::size_t stagingBytesFor(std::size_t cache_bytes);
  /// \brief The spill file's block cache at most (the other 1/8, blocks of up to 64 tiles, ≥ one tile) [bytes].
  static std::size_t blockCacheBytesFor(std::size_t cache_bytes);
  /// \brief Memory a spilled tile keeps besides the file: its summary and its entry in the file's index [bytes].
  static constexpr std::size_t spilledTileBytes() { return sizeof(TileSummary) + sizeof(std::int32_t); }

  std::int64_t tilesAcross() const { return tiles_x_; }  ///< tile columns (tile index = row · tilesAcross() + column)
  /// \brief Tile \p tile's kTileSide² pixels (row-major; 0 beyond the map's edge), nullptr if untouched; a spilled
  /// tile is read into \p scratch (kTileSide² floats) without entering the cache.
  const float* tileData(std::int64_t tile, float* scratch) const { return tileForRead(tile, scratch); }
  /// \brief Every resident tile to the spill file (in batches of one eviction), and their buffers back to the system.
  /// For a map that spilled, once its last writes are done: a pass in tile order (regions()) reads each tile once and
  /// needs no cache, so the tiles' share of cache_bytes is memory the end of a run can use. Values are unchanged; a
  /// later read brings tiles back as usual. \throws InputError naming the folder if the spill file cannot be written
  void releaseTiles() const;

private:
  struct Slot
  {
    std::int64_t tile = 0;          ///< its index in the directory
    std::int64_t file_offset = -1;  ///< where the tile lives in the spill file (-1: never spilled)
    std::uint64_t last_use = 0;
    float* data = nullptr;  ///< resident buffer, or nullptr when spilled
    bool dirty = true;      ///< changed since it was last written to the file
  };
  float* tileForWrite(std::int64_t tile) const;
  float* residentTile(std::int64_t tile) const;
  const float* tileForRead(std::int64_t tile, float* scratch) const;
  void makeRoom() const;
  void spillOldest(std::size_t count) const;  ///< the \p count least recently used resident tiles to the file
  /// \brief Σ and max of one tile's pixels, as summarise() combines them.
  struct TileSummary
  {
    double sums[8] = {};  ///< lane k: Σ of pixels i ≡ k (mod 8), in pixel order
    float max = 0.0f;
  };
  static TileSummary summariseTile(const float* data);
  void summarise() const;
  void load(Slot& slot) const;       ///< a spilled tile back, with its neighbours in the file
  void bringBack(Slot& slot) const;  ///< a spilled tile back
  static std::size_t fileTileOf(std::int64_t offset) { return static_cast<std::size_t>(offset) / kTileBytes; }

  Eigen::Vector2d origin_;
  double pixel_ = 0.0;
  std::int64_t width_ = 0, height_ = 0, tiles_x_ = 0, tiles_y_ = 0;
  std::size_t max_resident_ = 0;
  mutable std::vector<std::int32_t> slot_of_tile_;  ///< -1: untouched
  mutable std::vector<Slot> slots_;
  mutable std::vector<std::int32_t> slot_of_file_tile_;  ///< slot of each tile of the spill file, by offset
  mutable std::deque<TileSummary>
      spilled_summaries_;                       ///< each spilled tile's summary as last written (no regrowth copy)
  mutable std::vector<AlignedFloats> buffers_;  ///< slabs of tile buffers, every one ever allocated
  mutable std::size_t allocated_tiles_ = 0;     ///< tile buffers in the slabs
  mutable std::vector<float*> free_buffers_;
  mutable std::size_t resident_ = 0, peak_resident_ = 0, spilled_tiles_ = 0;
  mutable std::uint64_t clock_ = 0;
  mutable TileSpillFile spill_;
  mutable std::int64_t hot_tile_ = -1;  ///< the tile last returned (a stencil's rows hit 1–4 tiles)
  mutable std::size_t hot_slot_ = 0;
  mutable float* hot_data_ = nullptr;   ///< valid until the next makeRoom()
  mutable bool hot_written_ = false;    ///< the hot tile came through tileForWrite (dirty, summary stale)
  mutable bool summary_valid_ = false;  ///< total_ and peak_ match the tiles
  mutable double total_ = 0.0;
  mutable float peak_ = 0.0f;
};
}  // namespace scanhead
