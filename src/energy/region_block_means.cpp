/// \file region_block_means.cpp
#include "region_block_means.hpp"

#include <algorithm>

namespace scanhead
{
namespace
{
EnergyMap emptyGridOf(const TiledEnergyMap& map, std::int64_t c0, std::int64_t r0, std::int64_t out_w,
                      std::int64_t out_h, std::int64_t f)
{
  const double big = map.pixel() * static_cast<double>(f);
  const Eigen::Vector2d lo =
      map.origin() + map.pixel() * Eigen::Vector2d(static_cast<double>(c0), static_cast<double>(r0));
  return EnergyMap(lo, lo + big * Eigen::Vector2d(static_cast<double>(out_w), static_cast<double>(out_h)), big);
}
}  // namespace

RegionBlockMeans::RegionBlockMeans(const TiledEnergyMap& map, const TiledEnergyMap::RegionRequest& request)
{
  const std::int64_t width = map.width(), height = map.height();
  c0_ = std::clamp<std::int64_t>(request.col0, 0, std::max<std::int64_t>(0, width - 1));
  r0_ = std::clamp<std::int64_t>(request.row0, 0, std::max<std::int64_t>(0, height - 1));
  c1_ = std::clamp<std::int64_t>(request.col0 + request.w, c0_ + 1, std::max<std::int64_t>(c0_ + 1, width));
  r1_ = std::clamp<std::int64_t>(request.row0 + request.h, r0_ + 1, std::max<std::int64_t>(r0_ + 1, height));
  f_ = std::max(1, request.factor);
  tiles_x_ = map.tilesAcross();
  tiles_y_ = (height + kSide - 1) / kSide;
  const std::int64_t out_w = (c1_ - c0_ + f_ - 1) / f_;
  out_h_ = (r1_ - r0_ + f_ - 1) / f_;
  out_.emplace(emptyGridOf(map, c0_, r0_, out_w, out_h_, f_));
  out_cols_ = static_cast<std::size_t>(out_->width());
  ring_rows_ = (kSide + f_ - 1) / f_ + 1;
  sum_.assign(static_cast<std::size_t>(ring_rows_) * out_cols_, 0.0);
}

double* RegionBlockMeans::ringRow(std::int64_t out_row)
{
  return sum_.data() + static_cast<std::size_t>(out_row % ring_rows_) * out_cols_;
}

void RegionBlockMeans::writeRowsBefore(std::int64_t end_row)
{
  const double inv = 1.0 / static_cast<double>(f_ * f_);
  for (; next_out_row_ < end_row; ++next_out_row_)
  {
    double* ring = ringRow(next_out_row_);
    float* row = out_->row(static_cast<int>(next_out_row_));
    for (std::size_t c = 0; c < out_cols_; ++c)
    {
      row[c] = static_cast<float>(ring[c] * inv);
      ring[c] = 0.0;
    }
  }
}

void RegionBlockMeans::addTile(std::int64_t tj, std::int64_t ti, const float* data)
{
  const std::int64_t f = f_, c0 = c0_, r0 = r0_;
  const std::int64_t rr0 = std::max(r0, tj * kSide), rr1 = std::min(r1_, (tj + 1) * kSide);
  const std::int64_t cc0 = std::max(c0, ti * kSide), cc1 = std::min(c1_, (ti + 1) * kSide);
  for (std::int64_t r = rr0; r < rr1; ++r)
  {
    const float* in = data + (r - tj * kSide) * kSide - ti * kSide;
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

void RegionBlockMeans::endTileRow(std::int64_t tj)
{
  // Output rows whose map rows all lie below the next band: complete.
  writeRowsBefore(std::min<std::int64_t>(out_h_, ((tj + 1) * kSide - r0_) / f_));
}

EnergyMap RegionBlockMeans::finish()
{
  writeRowsBefore(out_h_);
  sum_ = {};
  return std::move(*out_);
}
}  // namespace scanhead
