/// \file image.hpp
/// \brief Plain raster images for output files (PNG): 8-bit RGB and 16-bit gray.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace scanhead
{
/// \brief 8-bit RGB image; rows top to bottom, 3 bytes (R, G, B) per pixel.
struct RgbImage
{
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> rgb;  ///< size 3·width·height

  RgbImage() = default;
  RgbImage(int w, int h)
    : width(w)
    , height(h)
    , rgb(3 * static_cast<std::size_t>(w) * static_cast<std::size_t>(h), 0)
  {
  }
  std::uint8_t* pixel(int x, int y) { return rgb.data() + 3 * (static_cast<std::size_t>(y) * width + x); }
  const std::uint8_t* pixel(int x, int y) const { return rgb.data() + 3 * (static_cast<std::size_t>(y) * width + x); }
};

/// \brief 16-bit gray image; rows top to bottom.
struct Gray16Image
{
  int width = 0;
  int height = 0;
  std::vector<std::uint16_t> gray;  ///< size width·height

  Gray16Image() = default;
  Gray16Image(int w, int h)
    : width(w)
    , height(h)
    , gray(static_cast<std::size_t>(w) * static_cast<std::size_t>(h), 0)
  {
  }
  std::uint16_t& at(int x, int y) { return gray[static_cast<std::size_t>(y) * width + x]; }
  std::uint16_t at(int x, int y) const { return gray[static_cast<std::size_t>(y) * width + x]; }
};
}  // namespace scanhead
