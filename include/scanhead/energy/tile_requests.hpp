/// \file tile_requests.hpp
/// \brief Which items (track samples, corner discs) need which tiles of a sparse map, for readers served by a pass
/// over the map that reads each tile once in its own order (TrackEnergySampler, DiscPeakSampler).
#pragma once

#include <algorithm>
#include <cstdint>
#include <vector>

#include "scanhead/energy/tiled_energy_map.hpp"

namespace scanhead
{
/// \brief (tile, item) pairs sorted by tile (8 B each: tile · 2^32 + item; a map has < 2^31 tiles), each marked once
/// a pass served its tile; the tiles no pass served are read from the map at the end.
class TileRequests
{
public:
  void add(std::int64_t tile, std::uint32_t item) { keys_.push_back(static_cast<std::uint64_t>(tile) << 32 | item); }
  /// \brief After the last add(): sorts the pairs by tile.
  void sort()
  {
    std::sort(keys_.begin(), keys_.end());
    served_.assign(keys_.size(), 0);
  }
  /// \brief Calls f(item) for each item that needs \p tile, and marks them served (a tile may come twice).
  template <class F>
  void forTile(std::int64_t tile, F&& f)
  {
    const auto t = static_cast<std::uint64_t>(tile);
    for (auto it = std::lower_bound(keys_.begin(), keys_.end(), t << 32); it != keys_.end() && (*it >> 32) == t; ++it)
    {
      served_[static_cast<std::size_t>(it - keys_.begin())] = 1;
      f(static_cast<std::uint32_t>(*it));
    }
  }
  /// \brief Calls serve(tile, pixels) for each tile no pass served, in tile order, read from \p map (resident or
  /// spilled; untouched tiles, which read 0, are skipped); then frees the pairs.
  template <class F>
  void serveTheRest(const TiledEnergyMap& map, F&& serve)
  {
    std::vector<float> scratch(TiledEnergyMap::kTileBytes / sizeof(float));
    for (std::size_t k = 0; k < keys_.size(); ++k)
    {
      if (served_[k] || (k > 0 && (keys_[k - 1] >> 32) == (keys_[k] >> 32)))
        continue;  // served, or its tile was served just before
      const auto tile = static_cast<std::int64_t>(keys_[k] >> 32);
      if (const float* data = map.tileData(tile, scratch.data()))
        serve(tile, data);
    }
    keys_ = {};
    served_ = {};
  }

private:
  std::vector<std::uint64_t> keys_;
  std::vector<char> served_;  ///< per pair
};
}  // namespace scanhead
