/// \file png_writer.cpp
#include "scanhead/report/png_writer.hpp"
#include "scanhead/common/text_file.hpp"

#include <zlib.h>

#include <algorithm>
#include <stdexcept>
#include <string>

namespace scanhead
{
namespace
{
constexpr std::size_t kIdatChunkBytes = 1u << 20;  // split the zlib stream into 1 MiB IDAT chunks

void putU32(std::vector<std::uint8_t>& out, std::uint32_t v)
{
  out.push_back(static_cast<std::uint8_t>(v >> 24));
  out.push_back(static_cast<std::uint8_t>(v >> 16));
  out.push_back(static_cast<std::uint8_t>(v >> 8));
  out.push_back(static_cast<std::uint8_t>(v));
}

/// \brief Appends a chunk: length, type, data, CRC-32(type + data).
void putChunk(std::vector<std::uint8_t>& out, const char type[4], const std::uint8_t* data, std::size_t size)
{
  putU32(out, static_cast<std::uint32_t>(size));
  const std::size_t type_at = out.size();
  out.insert(out.end(), type, type + 4);
  out.insert(out.end(), data, data + size);
  uLong crc = crc32(0L, Z_NULL, 0);
  // crc32 takes a uInt length: feed in pieces (a chunk is at most kIdatChunkBytes here anyway).
  const std::uint8_t* p = out.data() + type_at;
  std::size_t left = size + 4;
  while (left > 0)
  {
    const uInt n = static_cast<uInt>(std::min<std::size_t>(left, 1u << 30));
    crc = crc32(crc, p, n);
    p += n;
    left -= n;
  }
  putU32(out, static_cast<std::uint32_t>(crc));
}

void checkSize(int width, int height, std::size_t have, std::size_t per_pixel)
{
  if (width <= 0 || height <= 0 || width > (1 << 30) || height > (1 << 30))
  {
    throw std::invalid_argument("png: image size must be positive (got " + std::to_string(width) + " x " +
                                std::to_string(height) + ")");
  }
  const std::size_t want = static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * per_pixel;
  if (have != want)
  {
    throw std::invalid_argument("png: pixel buffer holds " + std::to_string(have) + " values, " + std::to_string(want) +
                                " expected for " + std::to_string(width) + " x " + std::to_string(height));
  }
}

/// \brief Signature, IHDR, IDAT (zlib of the filtered scanlines), IEND.
std::vector<std::uint8_t> assemble(int width, int height, std::uint8_t bit_depth, std::uint8_t colour_type,
                                   const std::vector<std::uint8_t>& scanlines)
{
  std::vector<std::uint8_t> out = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  std::vector<std::uint8_t> ihdr;
  putU32(ihdr, static_cast<std::uint32_t>(width));
  putU32(ihdr, static_cast<std::uint32_t>(height));
  ihdr.push_back(bit_depth);
  ihdr.push_back(colour_type);
  ihdr.push_back(0);  // compression: deflate
  ihdr.push_back(0);  // filter method 0
  ihdr.push_back(0);  // no interlace
  putChunk(out, "IHDR", ihdr.data(), ihdr.size());

  uLongf compressed_size = compressBound(static_cast<uLong>(scanlines.size()));
  std::vector<std::uint8_t> compressed(compressed_size);
  const int rc = compress2(compressed.data(), &compressed_size, scanlines.data(), static_cast<uLong>(scanlines.size()),
                           Z_DEFAULT_COMPRESSION);
  if (rc != Z_OK)
  {
    throw std::runtime_error("png: zlib compress2 failed (code " + std::to_string(rc) + ")");
  }
  for (std::size_t at = 0; at < compressed_size; at += kIdatChunkBytes)
  {
    putChunk(out, "IDAT", compressed.data() + at, std::min<std::size_t>(kIdatChunkBytes, compressed_size - at));
  }
  putChunk(out, "IEND", nullptr, 0);
  return out;
}

void writeFile(const std::string& path, const std::vector<std::uint8_t>& bytes)
{
  writeFileBytes(path, bytes.data(), bytes.size());
}
}  // namespace

std::vector<std::uint8_t> encodePng(const RgbImage& image)
{
  checkSize(image.width, image.height, image.rgb.size(), 3);
  const std::size_t row = 3 * static_cast<std::size_t>(image.width);
  std::vector<std::uint8_t> lines;
  lines.reserve((row + 1) * static_cast<std::size_t>(image.height));
  for (int y = 0; y < image.height; ++y)
  {
    lines.push_back(0);  // filter type None
    const std::uint8_t* src = image.rgb.data() + row * static_cast<std::size_t>(y);
    lines.insert(lines.end(), src, src + row);
  }
  return assemble(image.width, image.height, 8, 2, lines);
}

std::vector<std::uint8_t> encodePng(const Gray16Image& image)
{
  checkSize(image.width, image.height, image.gray.size(), 1);
  std::vector<std::uint8_t> lines;
  lines.reserve((2 * static_cast<std::size_t>(image.width) + 1) * static_cast<std::size_t>(image.height));
  for (int y = 0; y < image.height; ++y)
  {
    lines.push_back(0);  // filter type None
    for (int x = 0; x < image.width; ++x)
    {
      const std::uint16_t v = image.at(x, y);
      lines.push_back(static_cast<std::uint8_t>(v >> 8));  // PNG samples are big-endian
      lines.push_back(static_cast<std::uint8_t>(v & 0xFF));
    }
  }
  return assemble(image.width, image.height, 16, 0, lines);
}

void writePng(const std::string& path, const RgbImage& image)
{
  writeFile(path, encodePng(image));
}

void writePng(const std::string& path, const Gray16Image& image)
{
  writeFile(path, encodePng(image));
}
}  // namespace scanhead
