/// \file png_writer.hpp
/// \brief Minimal PNG encoder (zlib): 8-bit RGB and 16-bit gray, no interlace, filter type 0.
///
/// Layout per the PNG specification (ISO/IEC 15948): signature, IHDR, IDAT chunks holding the
/// zlib stream of the scanlines (each prefixed by its filter byte), IEND; every chunk carries the
/// CRC-32 of its type and data.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "scanhead/report/image.hpp"

namespace scanhead
{
/// \brief PNG file bytes of an RGB image (colour type 2, bit depth 8).
/// \throws std::invalid_argument if the size is not positive or the pixel buffer does not match it
std::vector<std::uint8_t> encodePng(const RgbImage& image);

/// \brief PNG file bytes of a 16-bit gray image (colour type 0, bit depth 16, big-endian samples).
/// \throws std::invalid_argument if the size is not positive or the pixel buffer does not match it
std::vector<std::uint8_t> encodePng(const Gray16Image& image);

/// \brief Writes encodePng(image) to \p path.
/// \throws std::runtime_error naming the path if the file cannot be written
void writePng(const std::string& path, const RgbImage& image);
void writePng(const std::string& path, const Gray16Image& image);
}  // namespace scanhead
