/// \file test_tiff_writer.cpp
/// \brief The float TIFF writer read back by an independent minimal TIFF parser written here
/// (header, IFD order and alignment, every tag's type, count and value, strips reassembled, pixels
/// bit for bit including NaN, ±inf, −0 and denormals), the atomic write and its errors, and, if
/// /usr/bin/python3 has PIL, the file opened by PIL.
#include <gtest/gtest.h>

#include <sys/stat.h>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <map>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "scanhead/common/errors.hpp"
#include "scanhead/report/tiff_writer.hpp"

using scanhead::encodeFloatTiff;
using scanhead::TiffScale;

namespace
{
std::uint32_t u16(const std::vector<std::uint8_t>& b, std::size_t at)
{
  return b.at(at) | (b.at(at + 1) << 8);
}

std::uint32_t u32(const std::vector<std::uint8_t>& b, std::size_t at)
{
  return u16(b, at) | (u16(b, at + 2) << 16);
}

std::uint64_t u64(const std::vector<std::uint8_t>& b, std::size_t at)
{
  return u32(b, at) | (static_cast<std::uint64_t>(u32(b, at + 4)) << 32);
}

double f64(const std::vector<std::uint8_t>& b, std::size_t at)
{
  const std::uint64_t bits = u64(b, at);
  double v;
  std::memcpy(&v, &bits, sizeof v);
  return v;
}

std::uint32_t floatBits(float v)
{
  std::uint32_t bits;
  std::memcpy(&bits, &v, sizeof bits);
  return bits;
}

/// \brief One IFD entry, its values decoded by type.
struct Tag
{
  std::uint32_t type = 0, count = 0;
  std::vector<std::uint64_t> ints;  ///< SHORT, LONG; RATIONAL as numerator, denominator pairs
  std::vector<double> reals;        ///< DOUBLE
  std::string text;                 ///< ASCII, without the final NUL
};

struct Tiff
{
  std::map<int, Tag> tags;
  std::vector<int> order;  ///< tags as they appear in the IFD
  std::vector<std::uint8_t> pixels;
};

/// \brief Parses a little-endian single-IFD TIFF per TIFF 6.0 §2; strips concatenated in order.
Tiff parse(const std::vector<std::uint8_t>& b)
{
  Tiff t;
  EXPECT_GE(b.size(), 8u);
  EXPECT_EQ(b[0], 'I');
  EXPECT_EQ(b[1], 'I');
  EXPECT_EQ(u16(b, 2), 42u);
  const std::size_t ifd = u32(b, 4);
  EXPECT_EQ(ifd % 2, 0u) << "IFD on a word boundary";
  const std::size_t n = u16(b, ifd);
  const std::map<std::uint32_t, std::size_t> type_size = {{1, 1}, {2, 1}, {3, 2}, {4, 4}, {5, 8}, {12, 8}};
  for (std::size_t i = 0; i < n; ++i)
  {
    const std::size_t e = ifd + 2 + 12 * i;
    const int tag = static_cast<int>(u16(b, e));
    Tag v;
    v.type = u16(b, e + 2);
    v.count = u32(b, e + 4);
    EXPECT_TRUE(type_size.count(v.type)) << "tag " << tag << " type " << v.type;
    const std::size_t bytes = type_size.at(v.type) * v.count;
    const std::size_t at = bytes <= 4 ? e + 8 : u32(b, e + 8);
    if (bytes > 4)
    {
      EXPECT_EQ(at % 2, 0u) << "tag " << tag << " value on a word boundary";
    }
    EXPECT_LE(at + bytes, b.size()) << "tag " << tag;
    for (std::uint32_t k = 0; k < v.count; ++k)
    {
      switch (v.type)
      {
        case 2:
          v.text.push_back(static_cast<char>(b.at(at + k)));
          break;
        case 3:
          v.ints.push_back(u16(b, at + 2 * k));
          break;
        case 4:
          v.ints.push_back(u32(b, at + 4 * k));
          break;
        case 5:
          v.ints.push_back(u32(b, at + 8 * k));
          v.ints.push_back(u32(b, at + 8 * k + 4));
          break;
        case 12:
          v.reals.push_back(f64(b, at + 8 * k));
          break;
      }
    }
    if (v.type == 2)
    {
      EXPECT_EQ(v.text.back(), '\0') << "ASCII ends with NUL";
      v.text.pop_back();
    }
    if (!t.order.empty())
    {
      EXPECT_LT(t.order.back(), tag) << "tags in ascending order";
    }
    t.order.push_back(tag);
    t.tags[tag] = v;
  }
  EXPECT_EQ(u32(b, ifd + 2 + 12 * n), 0u) << "a single IFD";
  const Tag& offsets = t.tags.at(273);
  const Tag& counts = t.tags.at(279);
  EXPECT_EQ(offsets.ints.size(), counts.ints.size());
  for (std::size_t s = 0; s < offsets.ints.size(); ++s)
  {
    EXPECT_LE(offsets.ints[s] + counts.ints[s], b.size());
    t.pixels.insert(t.pixels.end(), b.begin() + offsets.ints[s], b.begin() + offsets.ints[s] + counts.ints[s]);
  }
  return t;
}

std::vector<std::uint64_t> ints(const Tiff& t, int tag)
{
  return t.tags.count(tag) ? t.tags.at(tag).ints : std::vector<std::uint64_t>{};
}

/// \brief Every tag of the writer's layout; the pixels bit for bit.
void checkFile(const std::vector<std::uint8_t>& bytes, int width, int height, const std::vector<float>& data,
               const TiffScale& scale)
{
  const Tiff t = parse(bytes);
  const std::vector<int> expected_order =
      scale.description.empty()
          ? std::vector<int>{256, 257, 258, 259, 262, 273, 277, 278, 279, 282, 283, 284, 296, 339, 33550, 33922, 34735}
          : std::vector<int>{256, 257, 258, 259, 262, 270, 273,   277,   278,
                             279, 282, 283, 284, 296, 339, 33550, 33922, 34735};
  EXPECT_EQ(t.order, expected_order);
  EXPECT_EQ(ints(t, 256), std::vector<std::uint64_t>{static_cast<std::uint64_t>(width)});
  EXPECT_EQ(ints(t, 257), std::vector<std::uint64_t>{static_cast<std::uint64_t>(height)});
  EXPECT_EQ(ints(t, 258), std::vector<std::uint64_t>{32});
  EXPECT_EQ(ints(t, 259), std::vector<std::uint64_t>{1});
  EXPECT_EQ(ints(t, 262), std::vector<std::uint64_t>{1});
  EXPECT_EQ(ints(t, 277), std::vector<std::uint64_t>{1});
  EXPECT_EQ(ints(t, 284), std::vector<std::uint64_t>{1});
  EXPECT_EQ(ints(t, 296), std::vector<std::uint64_t>{3});
  EXPECT_EQ(ints(t, 339), std::vector<std::uint64_t>{3});
  if (!scale.description.empty())
  {
    EXPECT_EQ(t.tags.at(270).text, scale.description);
  }
  // Strips: RowsPerStrip rows each (the last one the rest), as StripByteCounts says.
  ASSERT_EQ(ints(t, 278).size(), 1u);
  const std::uint64_t rows_per_strip = ints(t, 278)[0];
  const std::vector<std::uint64_t> counts = ints(t, 279);
  ASSERT_EQ(counts.size(), (height + rows_per_strip - 1) / rows_per_strip);
  for (std::size_t s = 0; s < counts.size(); ++s)
    EXPECT_EQ(counts[s], 4u * width * std::min<std::uint64_t>(rows_per_strip, height - s * rows_per_strip));
  // Resolution in pixels per centimetre, as a fraction.
  for (int tag : {282, 283})
  {
    const std::vector<std::uint64_t> r = ints(t, tag);
    ASSERT_EQ(r.size(), 2u);
    ASSERT_GT(r[1], 0u);
    const double want = 0.01 / (tag == 282 ? scale.pixel_x_m : scale.pixel_y_m);
    EXPECT_NEAR(static_cast<double>(r[0]) / static_cast<double>(r[1]), want, want * 1e-12) << "tag " << tag;
  }
  // GeoTIFF: exact doubles.
  const Tag& pixel_scale = t.tags.at(33550);
  EXPECT_EQ(pixel_scale.type, 12u);
  EXPECT_EQ(pixel_scale.reals, (std::vector<double>{scale.pixel_x_m, scale.pixel_y_m, 0.0}));
  EXPECT_EQ(t.tags.at(33922).reals, (std::vector<double>{0.0, 0.0, 0.0, scale.x_left_m, scale.y_top_m, 0.0}));
  EXPECT_EQ(ints(t, 34735),
            (std::vector<std::uint64_t>{1, 1, 0, 3, 1024, 0, 1, 32767, 1025, 0, 1, 1, 3076, 0, 1, 9001}));
  // Pixels, bit for bit.
  ASSERT_EQ(t.pixels.size(), 4u * data.size());
  for (std::size_t i = 0; i < data.size(); ++i)
    ASSERT_EQ(u32(t.pixels, 4 * i), floatBits(data[i])) << "pixel " << i;
}

std::vector<std::uint8_t> readFile(const std::string& path)
{
  std::ifstream f(path, std::ios::binary);
  return std::vector<std::uint8_t>((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
}

bool exists(const std::string& path)
{
  struct stat st;
  return ::stat(path.c_str(), &st) == 0;
}

TiffScale scale5um()
{
  TiffScale s;
  s.pixel_x_m = 5e-6;
  s.pixel_y_m = 5e-6;
  s.x_left_m = -0.0125;
  s.y_top_m = 0.0375;
  s.description = "energy density [J/m^2], pixel 5e-06 m";
  return s;
}
}  // namespace

TEST(TiffWriter, SmallImageSpecialValues)
{
  const int w = 4, h = 3;
  const std::vector<float> data = {0.0f,
                                   -0.0f,
                                   1.0f,
                                   -1.5f,
                                   std::numeric_limits<float>::quiet_NaN(),
                                   std::numeric_limits<float>::infinity(),
                                   -std::numeric_limits<float>::infinity(),
                                   std::numeric_limits<float>::max(),
                                   std::numeric_limits<float>::denorm_min(),
                                   std::numeric_limits<float>::min(),
                                   3.14159274f,
                                   1234567.875f};
  const TiffScale scale = scale5um();
  const std::vector<std::uint8_t> bytes = encodeFloatTiff(w, h, data.data(), scale);
  checkFile(bytes, w, h, data, scale);
  const Tiff t = parse(bytes);
  EXPECT_EQ(ints(t, 273).size(), 1u) << "one strip";
  EXPECT_EQ(ints(t, 282), (std::vector<std::uint64_t>{2000, 1})) << "5 µm: 2000 pixels/cm";
  EXPECT_EQ(ints(t, 273)[0] % 8, 0u) << "pixels 8-byte aligned";
  EXPECT_EQ(bytes.size(), ints(t, 273)[0] + 4u * w * h) << "the pixels end the file";
}

TEST(TiffWriter, ManyStripsAndUnequalPixels)
{
  const int w = 1000, h = 77;  // 4000-byte rows: 16 rows a strip, 5 strips, the last one 13 rows
  std::vector<float> data(static_cast<std::size_t>(w) * h);
  std::mt19937 rng(11);  // fixed seed
  for (float& v : data)
  {
    const std::uint32_t bits = static_cast<std::uint32_t>(rng());
    std::memcpy(&v, &bits, sizeof v);  // any bit pattern, NaN payloads included
  }
  TiffScale scale;
  scale.pixel_x_m = 70e-6;
  scale.pixel_y_m = 3e-7;
  scale.x_left_m = 1e-3;
  scale.y_top_m = -2e-3;
  const std::vector<std::uint8_t> bytes = encodeFloatTiff(w, h, data.data(), scale);
  checkFile(bytes, w, h, data, scale);
  const Tiff t = parse(bytes);
  EXPECT_EQ(ints(t, 278), std::vector<std::uint64_t>{16});
  EXPECT_EQ(ints(t, 273).size(), 5u);
  EXPECT_EQ(ints(t, 282), (std::vector<std::uint64_t>{1000, 7})) << "70 µm: 1000/7 pixels/cm";
  EXPECT_EQ(ints(t, 283), (std::vector<std::uint64_t>{100000, 3})) << "0.3 µm: 100000/3 pixels/cm";
  EXPECT_EQ(t.tags.count(270), 0u) << "no description, no tag";
  // One row wider than a strip: a strip per row.
  std::vector<float> wide(20000 * 3, 1.0f);
  const Tiff tw = parse(encodeFloatTiff(20000, 3, wide.data(), scale5um()));
  EXPECT_EQ(ints(tw, 278), std::vector<std::uint64_t>{1});
  EXPECT_EQ(ints(tw, 279), (std::vector<std::uint64_t>{80000, 80000, 80000}));
}

TEST(TiffWriter, WritesAtomically)
{
  const std::string path = ::testing::TempDir() + "scanhead_test_tiff_writer.tif";
  std::vector<float> data = {1.0f, 2.0f, 3.0f, 4.0f, 5.0f, 6.0f};
  scanhead::writeFloatTiff(path, 3, 2, data.data(), scale5um());
  EXPECT_EQ(readFile(path), encodeFloatTiff(3, 2, data.data(), scale5um()));
  EXPECT_FALSE(exists(path + ".tmp"));
  data[0] = 42.0f;  // over an existing file
  scanhead::writeFloatTiff(path, 2, 3, data.data(), scale5um());
  EXPECT_EQ(readFile(path), encodeFloatTiff(2, 3, data.data(), scale5um()));
  std::remove(path.c_str());

  const std::string missing = "/nonexistent_dir_xyz/map.tif";
  try
  {
    scanhead::writeFloatTiff(missing, 3, 2, data.data(), scale5um());
    FAIL();
  }
  catch (const scanhead::InputError& e)
  {
    EXPECT_NE(std::string(e.what()).find(missing), std::string::npos) << e.what();
  }
  // The target is a directory: the rename fails, the temporary file is removed.
  const std::string dir = ::testing::TempDir() + "scanhead_test_tiff_writer_dir";
  ::mkdir(dir.c_str(), 0700);
  try
  {
    scanhead::writeFloatTiff(dir, 3, 2, data.data(), scale5um());
    FAIL();
  }
  catch (const scanhead::InputError& e)
  {
    EXPECT_NE(std::string(e.what()).find(dir + ": cannot rename"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(exists(dir + ".tmp"));
  ::rmdir(dir.c_str());
}

TEST(TiffWriter, BadArguments)
{
  const float one = 1.0f;
  const TiffScale ok = scale5um();
  EXPECT_THROW(encodeFloatTiff(0, 1, &one, ok), std::invalid_argument);
  EXPECT_THROW(encodeFloatTiff(1, -1, &one, ok), std::invalid_argument);
  EXPECT_THROW(encodeFloatTiff(1, 1, nullptr, ok), std::invalid_argument);
  EXPECT_THROW(encodeFloatTiff(40000, 40000, &one, ok), std::invalid_argument) << "6.4 GB: beyond classic TIFF";
  for (double bad : {0.0, -5e-6, std::nan(""), std::numeric_limits<double>::infinity(),
                     1e-15 /* 1e13 pixels/cm: no 32-bit fraction */})
  {
    TiffScale s = ok;
    s.pixel_y_m = bad;
    EXPECT_THROW(encodeFloatTiff(1, 1, &one, s), std::invalid_argument) << bad;
  }
  TiffScale s = ok;
  s.x_left_m = NAN;
  EXPECT_THROW(encodeFloatTiff(1, 1, &one, s), std::invalid_argument);
  s = ok;
  s.description = "energy density [J/m\xc2\xb2]";  // UTF-8 ²: not ASCII
  EXPECT_THROW(encodeFloatTiff(1, 1, &one, s), std::invalid_argument);
  s.description = std::string("a\0b", 3);
  EXPECT_THROW(encodeFloatTiff(1, 1, &one, s), std::invalid_argument);
}

// An independent, widely used reader: PIL (Pillow) opens the file as a 32-bit float image, with the
// same pixels and tags. Skipped if /usr/bin/python3 has no PIL.
TEST(TiffWriter, PilReadsIt)
{
  if (std::system("/usr/bin/python3 -c 'import PIL' >/dev/null 2>&1") != 0)
    GTEST_SKIP() << "no PIL for /usr/bin/python3";
  const int w = 7, h = 5;
  std::vector<float> data(w * h);
  for (int i = 0; i < w * h; ++i)
    data[i] = i == 3 ? std::numeric_limits<float>::infinity() : 0.1f * static_cast<float>(i * i) - 7.0f;
  const std::string path = ::testing::TempDir() + "scanhead_test_tiff_writer_pil.tif";
  scanhead::writeFloatTiff(path, w, h, data.data(), scale5um());
  const std::string script =
      "import struct, sys\n"
      "from PIL import Image\n"
      "im = Image.open(sys.argv[1])\n"
      "print(im.format, im.mode, im.size[0], im.size[1])\n"
      "print(' '.join(struct.pack('<f', im.getpixel((x, y))).hex() for y in range(im.size[1]) for x in "
      "range(im.size[0])))\n"
      "t = im.tag_v2\n"
      "print(t[270])\n"
      "print(' '.join(repr(v) for v in t[33550]))\n"
      "print(' '.join(repr(v) for v in t[33922]))\n"
      "print(float(t[282]), t[296])\n";
  const std::string script_path = ::testing::TempDir() + "scanhead_test_tiff_writer_pil.py";
  std::ofstream(script_path) << script;
  const std::string command = "/usr/bin/python3 " + script_path + " " + path + " 2>&1";
  FILE* pipe = ::popen(command.c_str(), "r");
  ASSERT_NE(pipe, nullptr);
  std::string output;
  char buffer[4096];
  while (std::fgets(buffer, sizeof buffer, pipe))
    output += buffer;
  const int status = ::pclose(pipe);
  std::remove(path.c_str());
  std::remove(script_path.c_str());
  ASSERT_EQ(status, 0) << output;

  std::string hex;
  for (float v : data)
  {
    char b[16];
    const std::uint32_t bits = floatBits(v);
    std::snprintf(b, sizeof b, "%02x%02x%02x%02x ", bits & 0xFF, (bits >> 8) & 0xFF, (bits >> 16) & 0xFF, bits >> 24);
    hex += b;
  }
  hex.back() = '\n';
  const std::string expected = "TIFF F 7 5\n" + hex +
                               "energy density [J/m^2], pixel 5e-06 m\n"
                               "5e-06 5e-06 0.0\n"
                               "0.0 0.0 0.0 -0.0125 0.0375 0.0\n"
                               "2000.0 3\n";
  EXPECT_EQ(output, expected);
}
