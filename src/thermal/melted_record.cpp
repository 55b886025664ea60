/// \file melted_record.cpp
/// \brief Sparse bit tiles of the melted cells.
#include "scanhead/thermal/melted_record.hpp"

#include <algorithm>
#include <vector>

namespace scanhead
{
std::int64_t MeltedRecord::tileKey(std::int64_t ti, std::int64_t tj)
{
  return static_cast<std::int64_t>((static_cast<std::uint64_t>(static_cast<std::uint32_t>(ti)) << 32) |
                                   static_cast<std::uint64_t>(static_cast<std::uint32_t>(tj)));
}

bool MeltedRecord::get(std::int64_t gi, std::int64_t gj) const
{
  const std::int64_t ti = tileOf(gi), tj = tileOf(gj);
  const auto it = tiles_.find(tileKey(ti, tj));
  if (it == tiles_.end())
    return false;
  return (it->second[static_cast<std::size_t>(gj - 64 * tj)] >> (gi - 64 * ti)) & 1u;
}

void MeltedRecord::set(std::int64_t gi, std::int64_t gj)
{
  const std::int64_t ti = tileOf(gi), tj = tileOf(gj);
  auto it = tiles_.find(tileKey(ti, tj));
  if (it == tiles_.end())
  {
    Tile empty;
    empty.fill(0);
    it = tiles_.emplace(tileKey(ti, tj), empty).first;
  }
  std::uint64_t& word = it->second[static_cast<std::size_t>(gj - 64 * tj)];
  const std::uint64_t bit = std::uint64_t(1) << (gi - 64 * ti);
  if (!(word & bit))
  {
    word |= bit;
    ++count_;
  }
}

void MeltedRecord::readRun(std::int64_t gi, std::int64_t gj, int run, std::uint8_t* out) const
{
  const std::int64_t ti = tileOf(gi), tj = tileOf(gj);
  const auto it = tiles_.find(tileKey(ti, tj));
  if (it == tiles_.end())
    std::fill(out, out + run, std::uint8_t(0));
  else
  {
    const std::uint64_t word = it->second[static_cast<std::size_t>(gj - 64 * tj)];
    const int b0 = static_cast<int>(gi - 64 * ti);
    for (int r = 0; r < run; ++r)
      out[r] = static_cast<std::uint8_t>((word >> (b0 + r)) & 1u);
  }
}

MeltedRaster MeltedRecord::raster(double cell_m) const
{
  MeltedRaster r;
  r.cell_m = cell_m;
  r.count = count_;
  if (count_ == 0)
    return r;
  std::int64_t gi0 = INT64_MAX, gi1 = INT64_MIN, gj0 = INT64_MAX, gj1 = INT64_MIN;
  for (const auto& kv : tiles_)
  {
    const std::int64_t ti = static_cast<std::int32_t>(static_cast<std::uint64_t>(kv.first) >> 32);
    const std::int64_t tj = static_cast<std::int32_t>(static_cast<std::uint64_t>(kv.first) & 0xffffffffu);
    for (int b = 0; b < 64; ++b)
    {
      const std::uint64_t word = kv.second[static_cast<std::size_t>(b)];
      if (!word)
        continue;
      for (int a = 0; a < 64; ++a)
      {
        if ((word >> a) & 1u)
        {
          gi0 = std::min(gi0, 64 * ti + a);
          gi1 = std::max(gi1, 64 * ti + a);
          gj0 = std::min(gj0, 64 * tj + b);
          gj1 = std::max(gj1, 64 * tj + b);
        }
      }
    }
  }
  r.origin_i = gi0;
  r.origin_j = gj0;
  r.width = static_cast<int>(gi1 - gi0 + 1);
  r.height = static_cast<int>(gj1 - gj0 + 1);
  r.melted.assign(static_cast<std::size_t>(r.width) * r.height, 0);
  for (const auto& kv : tiles_)
  {
    const std::int64_t ti = static_cast<std::int32_t>(static_cast<std::uint64_t>(kv.first) >> 32);
    const std::int64_t tj = static_cast<std::int32_t>(static_cast<std::uint64_t>(kv.first) & 0xffffffffu);
    for (int b = 0; b < 64; ++b)
    {
      const std::uint64_t word = kv.second[static_cast<std::size_t>(b)];
      for (int a = 0; a < 64; ++a)
      {
        if ((word >> a) & 1u)
        {
          const std::int64_t x = 64 * ti + a - gi0, y = 64 * tj + b - gj0;
          r.melted[static_cast<std::size_t>(y) * r.width + static_cast<std::size_t>(x)] = 1;
        }
      }
    }
  }
  return r;
}
}  // namespace scanhead
