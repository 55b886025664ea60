/// \file melted_record.hpp
/// \brief The global, sparse record of the cells ever melted (the layer's memory beyond the moving
/// window): 64 × 64-cell bit tiles in a hash map, on the global grid of pitch cell_m.
#pragma once

#include <array>
#include <cstdint>
#include <unordered_map>

#include "scanhead/thermal/thermal_results.hpp"

namespace scanhead
{
/// \brief Set of melted global cells (gi, gj), cell (gi, gj) covering [gi·cell, (gi + 1)·cell) ×
/// [gj·cell, (gj + 1)·cell). Stored as tiles of 64 × 64 cells, bit a of word b of tile (ti, tj)
/// being cell (64·ti + a, 64·tj + b); tiles are created on the first set() in them and never removed
/// (a cell, once melted, stays so). Indices must fit in 32-bit tile indices (|gi|, |gj| < 2^37).
class MeltedRecord
{
public:
  /// \brief True if cell (gi, gj) has been set.
  bool get(std::int64_t gi, std::int64_t gj) const;
  /// \brief Marks cell (gi, gj) melted (count() += 1 if it was not).
  void set(std::int64_t gi, std::int64_t gj);
  /// \brief Cells set.
  std::uint64_t count() const { return count_; }

  /// \brief The states of the \p run cells (gi, gj) … (gi + run − 1, gj) into \p out (1 melted, 0 not).
  /// \pre the run stays within one tile: gi mod 64 + run ≤ 64
  void readRun(std::int64_t gi, std::int64_t gj, int run, std::uint8_t* out) const;

  /// \brief The record as a raster over the bounding box of the set cells (empty raster, count 0,
  /// when none is set), cells of side \p cell_m [m].
  MeltedRaster raster(double cell_m) const;

  /// \brief ⌊a / 64⌋ (the tile of cell index \p a).
  static std::int64_t tileOf(std::int64_t a) { return a >= 0 ? a / 64 : -((-a + 63) / 64); }

private:
  using Tile = std::array<std::uint64_t, 64>;  ///< 64 × 64 cells, bit i of word j
  static std::int64_t tileKey(std::int64_t ti, std::int64_t tj);

  std::unordered_map<std::int64_t, Tile> tiles_;
  std::uint64_t count_ = 0;
};
}  // namespace scanhead
