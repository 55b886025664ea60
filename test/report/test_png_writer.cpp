/// \file test_png_writer.cpp
/// \brief The PNG encoder decoded by an independent reader: chunk layout, CRCs (bitwise CRC-32
/// written here), header fields and the zlib-decompressed scanlines.
#include <gtest/gtest.h>
#include <zlib.h>

#include <cstdint>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "scanhead/report/png_writer.hpp"

using scanhead::encodePng;
using scanhead::Gray16Image;
using scanhead::RgbImage;

namespace
{
/// \brief CRC-32 (ISO 3309, reflected polynomial 0xEDB88320), bit by bit: independent of zlib.
std::uint32_t crc32Bitwise(const std::uint8_t* data, std::size_t n)
{
  std::uint32_t crc = 0xFFFFFFFFu;
  for (std::size_t i = 0; i < n; ++i)
  {
    crc ^= data[i];
    for (int b = 0; b < 8; ++b)
      crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1u)));
  }
  return crc ^ 0xFFFFFFFFu;
}

std::uint32_t u32(const std::uint8_t* p)
{
  return (std::uint32_t(p[0]) << 24) | (std::uint32_t(p[1]) << 16) | (std::uint32_t(p[2]) << 8) | p[3];
}

struct Decoded
{
  std::uint32_t width = 0, height = 0;
  int bit_depth = 0, colour_type = 0, compression = -1, filter = -1, interlace = -1;
  std::vector<std::string> chunk_types;
  std::vector<std::uint8_t> scanlines;  ///< inflated IDAT data
};

/// \brief Parses a PNG: checks the signature and every CRC, inflates the IDAT stream.
Decoded decode(const std::vector<std::uint8_t>& png, std::size_t raw_size)
{
  Decoded d;
  const std::uint8_t sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  EXPECT_TRUE(png.size() > 8 && std::equal(sig, sig + 8, png.begin()));
  std::vector<std::uint8_t> idat;
  std::size_t at = 8;
  while (at + 12 <= png.size())
  {
    const std::uint32_t len = u32(&png[at]);
    EXPECT_LE(at + 12 + len, png.size());
    const std::string type(png.begin() + at + 4, png.begin() + at + 8);
    const std::uint8_t* data = &png[at + 8];
    EXPECT_EQ(u32(data + len), crc32Bitwise(&png[at + 4], len + 4)) << "CRC of " << type;
    d.chunk_types.push_back(type);
    if (type == "IHDR")
    {
      EXPECT_EQ(len, 13u);
      d.width = u32(data);
      d.height = u32(data + 4);
      d.bit_depth = data[8];
      d.colour_type = data[9];
      d.compression = data[10];
      d.filter = data[11];
      d.interlace = data[12];
    }
    else if (type == "IDAT")
      idat.insert(idat.end(), data, data + len);
    at += 12 + len;
  }
  EXPECT_EQ(at, png.size());
  d.scanlines.resize(raw_size + 16);
  uLongf out_size = d.scanlines.size();
  EXPECT_EQ(uncompress(d.scanlines.data(), &out_size, idat.data(), idat.size()), Z_OK);
  d.scanlines.resize(out_size);
  return d;
}
}  // namespace

TEST(PngWriter, RgbRoundTrip)
{
  RgbImage img(5, 3);
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 5; ++x)
    {
      std::uint8_t* p = img.pixel(x, y);
      p[0] = static_cast<std::uint8_t>(40 * x);
      p[1] = static_cast<std::uint8_t>(100 * y);
      p[2] = static_cast<std::uint8_t>(7 * x + 11 * y);
    }
  const std::vector<std::uint8_t> png = encodePng(img);
  const Decoded d = decode(png, 3 * (1 + 15));
  EXPECT_EQ(d.width, 5u);
  EXPECT_EQ(d.height, 3u);
  EXPECT_EQ(d.bit_depth, 8);
  EXPECT_EQ(d.colour_type, 2);
  EXPECT_EQ(d.compression, 0);
  EXPECT_EQ(d.filter, 0);
  EXPECT_EQ(d.interlace, 0);
  ASSERT_GE(d.chunk_types.size(), 3u);
  EXPECT_EQ(d.chunk_types.front(), "IHDR");
  EXPECT_EQ(d.chunk_types.back(), "IEND");
  ASSERT_EQ(d.scanlines.size(), 3u * 16u);
  for (int y = 0; y < 3; ++y)
  {
    EXPECT_EQ(d.scanlines[16 * y], 0) << "filter byte";
    for (int x = 0; x < 5; ++x)
      for (int c = 0; c < 3; ++c)
        EXPECT_EQ(d.scanlines[16 * y + 1 + 3 * x + c], img.pixel(x, y)[c]);
  }
}

TEST(PngWriter, Gray16BigEndianRoundTrip)
{
  Gray16Image img(4, 2);
  const std::uint16_t values[8] = {0, 1, 255, 256, 0x1234, 0xABCD, 65534, 65535};
  for (int i = 0; i < 8; ++i)
    img.gray[i] = values[i];
  const Decoded d = decode(encodePng(img), 2 * (1 + 8));
  EXPECT_EQ(d.bit_depth, 16);
  EXPECT_EQ(d.colour_type, 0);
  ASSERT_EQ(d.scanlines.size(), 18u);
  for (int y = 0; y < 2; ++y)
  {
    EXPECT_EQ(d.scanlines[9 * y], 0);
    for (int x = 0; x < 4; ++x)
    {
      const std::uint16_t v = values[4 * y + x];
      EXPECT_EQ(d.scanlines[9 * y + 1 + 2 * x], v >> 8);
      EXPECT_EQ(d.scanlines[9 * y + 2 + 2 * x], v & 0xFF);
    }
  }
}

// Incompressible 800 x 800 RGB (1.9 MB): the zlib stream spans several IDAT chunks.
TEST(PngWriter, LargeImageSplitsIdat)
{
  RgbImage img(800, 800);
  std::mt19937 rng(3);  // fixed seed
  for (std::uint8_t& v : img.rgb)
    v = static_cast<std::uint8_t>(rng() & 0xFF);
  const Decoded d = decode(encodePng(img), 800u * 2401u);
  int idats = 0;
  for (const std::string& t : d.chunk_types)
    idats += t == "IDAT";
  EXPECT_GE(idats, 2);
  ASSERT_EQ(d.scanlines.size(), 800u * 2401u);
  for (int y = 0; y < 800; y += 97)
    EXPECT_TRUE(
        std::equal(img.rgb.begin() + 2400 * y, img.rgb.begin() + 2400 * (y + 1), d.scanlines.begin() + 2401 * y + 1));
}

TEST(PngWriter, FileAndErrors)
{
  RgbImage img(2, 2);
  img.rgb[0] = 200;
  const std::string path = ::testing::TempDir() + "scanhead_test_png_writer.png";
  scanhead::writePng(path, img);
  std::ifstream f(path, std::ios::binary);
  const std::vector<std::uint8_t> bytes((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  EXPECT_EQ(bytes, encodePng(img));
  std::remove(path.c_str());

  EXPECT_THROW(scanhead::writePng("/nonexistent_dir_xyz/a.png", img), std::runtime_error);
  RgbImage bad(2, 2);
  bad.rgb.pop_back();
  EXPECT_THROW(encodePng(bad), std::invalid_argument);
  EXPECT_THROW(encodePng(RgbImage()), std::invalid_argument);
}
