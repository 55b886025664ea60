/// \file region_block_means.hpp
/// \brief One region of a tiled map as block means, summed tile by tile while a pass in tile order reads the tiles
/// (TiledEnergyMap::region and regions).
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "scanhead/energy/energy_map.hpp"
#include "scanhead/energy/tiled_energy_map.hpp"

namespace scanhead
{
/// \brief The dense copy of TiledEnergyMap::region(col0, row0, w, h, factor): the pixels [col0, col0 + w) ×
/// [row0, row0 + h) clipped to the map, averaged over blocks of factor × factor pixels.
///
/// Sums in double per output pixel, tile by tile in the order the tiles are given (tile order: deterministic), then the
/// block mean. Only the output rows a band of tiles reaches are summed at once (a ring of them): the overview of a
/// whole layer needs 100 MB of doubles otherwise. An output row is complete once the band below its last map row is
/// done.
class RegionBlockMeans
{
public:
  RegionBlockMeans(const TiledEnergyMap& map, const TiledEnergyMap::RegionRequest& request);

  /// \brief The tiles the region covers: rows [firstTileRow(), lastTileRow()], columns [firstTileColumn(),
  /// lastTileColumn()] (empty when last < first).
  std::int64_t firstTileRow() const { return r0_ / kSide; }
  std::int64_t lastTileRow() const { return std::min((r1_ - 1) / kSide, tiles_y_ - 1); }
  std::int64_t firstTileColumn() const { return c0_ / kSide; }
  std::int64_t lastTileColumn() const { return std::min((c1_ - 1) / kSide, tiles_x_ - 1); }
  bool coversTileRow(std::int64_t tile_row) const { return tile_row >= firstTileRow() && tile_row <= lastTileRow(); }
  bool coversTile(std::int64_t tile_row, std::int64_t tile_column) const
  {
    return coversTileRow(tile_row) && tile_column >= firstTileColumn() && tile_column <= lastTileColumn();
  }

  /// \brief Adds tile (tile_row, tile_column)'s pixels (kTileSide², row-major); tiles come in tile order.
  void addTile(std::int64_t tile_row, std::int64_t tile_column, const float* data);
  /// \brief The band of tile row \p tile_row is done (every touched tile of it added).
  void endTileRow(std::int64_t tile_row);
  /// \brief The block means, once every tile row is done.
  EnergyMap finish();

private:
  static constexpr std::int64_t kSide = TiledEnergyMap::kTileSide;
  double* ringRow(std::int64_t out_row);
  void writeRowsBefore(std::int64_t end_row);

  std::int64_t c0_ = 0, r0_ = 0, c1_ = 0, r1_ = 0;  ///< the clipped pixels [c0, c1) × [r0, r1)
  std::int64_t f_ = 1;                              ///< block factor
  std::int64_t tiles_x_ = 0, tiles_y_ = 0;
  std::int64_t out_h_ = 0;
  std::optional<EnergyMap> out_;  ///< made once the clipped region is known
  std::size_t out_cols_ = 0;
  std::int64_t ring_rows_ = 0;
  std::vector<double> sum_;        ///< ring_rows × out_cols partial sums
  std::int64_t next_out_row_ = 0;  ///< the first output row not yet written
};
}  // namespace scanhead
