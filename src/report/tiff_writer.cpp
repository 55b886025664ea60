/// \file tiff_writer.cpp
#include "scanhead/report/tiff_writer.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <stdexcept>

#include "scanhead/common/errors.hpp"
#include "scanhead/common/number_text.hpp"
#include "scanhead/common/text_file.hpp"

namespace scanhead
{
namespace
{
constexpr std::size_t kStripBytes = 64 * 1024;  // target strip size
constexpr double kMaxU32 = 4294967295.0;

enum Type : std::uint16_t
{
  kAscii = 2,
  kShort = 3,
  kLong = 4,
  kRational = 5,
  kDouble = 12
};

void putU16(std::vector<std::uint8_t>& out, std::uint16_t v)
{
  out.push_back(static_cast<std::uint8_t>(v));
  out.push_back(static_cast<std::uint8_t>(v >> 8));
}

void putU32(std::vector<std::uint8_t>& out, std::uint32_t v)
{
  for (int s = 0; s < 32; s += 8)
    out.push_back(static_cast<std::uint8_t>(v >> s));
}

void putU32At(std::vector<std::uint8_t>& out, std::size_t at, std::uint32_t v)
{
  for (int s = 0; s < 4; ++s)
    out[at + s] = static_cast<std::uint8_t>(v >> (8 * s));
}

void putF64(std::vector<std::uint8_t>& out, double v)
{
  std::uint64_t bits;
  std::memcpy(&bits, &v, sizeof bits);
  for (int s = 0; s < 64; s += 8)
    out.push_back(static_cast<std::uint8_t>(bits >> s));
}

/// \brief A tag with its value already encoded (little-endian); values of more than 4 bytes go
/// out of line.
struct Entry
{
  std::uint16_t tag;
  std::uint16_t type;
  std::uint32_t count;
  std::vector<std::uint8_t> bytes;
};

Entry shorts(std::uint16_t tag, const std::vector<std::uint16_t>& values)
{
  Entry e{tag, kShort, static_cast<std::uint32_t>(values.size()), {}};
  for (std::uint16_t v : values)
    putU16(e.bytes, v);
  return e;
}

Entry longs(std::uint16_t tag, const std::vector<std::uint32_t>& values)
{
  Entry e{tag, kLong, static_cast<std::uint32_t>(values.size()), {}};
  for (std::uint32_t v : values)
    putU32(e.bytes, v);
  return e;
}

Entry doubles(std::uint16_t tag, const std::vector<double>& values)
{
  Entry e{tag, kDouble, static_cast<std::uint32_t>(values.size()), {}};
  for (double v : values)
    putF64(e.bytes, v);
  return e;
}

/// \brief x ≈ num/den with 32-bit terms: the last continued-fraction convergent that fits.
Entry rational(std::uint16_t tag, double x, const char* what)
{
  if (!(x >= 1.0 / kMaxU32 && x <= kMaxU32))
  {
    throw std::invalid_argument(std::string("tiff: ") + what + " of " + fullPrecisionText(x) +
                                " pixels/cm does not fit a 32-bit TIFF RATIONAL");
  }
  double h_prev = 0.0, h = 1.0, k_prev = 1.0, k = 0.0;  // convergents h/k, seeded with 0/1, 1/0
  double v = x;
  for (int i = 0; i < 64; ++i)
  {
    const double a = std::floor(v);
    const double h_next = a * h + h_prev, k_next = a * k + k_prev;
    if (h_next > kMaxU32 || k_next > kMaxU32)
      break;
    h_prev = h;
    h = h_next;
    k_prev = k;
    k = k_next;
    const double f = v - a;
    if (h / k == x || !(f > 0.0))
      break;
    v = 1.0 / f;
  }
  Entry e{tag, kRational, 1, {}};
  putU32(e.bytes, static_cast<std::uint32_t>(h));
  putU32(e.bytes, static_cast<std::uint32_t>(k));
  return e;
}

void checkScale(double v, const char* name)
{
  if (!(v > 0.0) || !std::isfinite(v))
    throw std::invalid_argument(std::string("tiff: ") + name + " must be finite and > 0 (got " + fullPrecisionText(v) +
                                ")");
}
}  // namespace

std::vector<std::uint8_t> encodeFloatTiff(int width, int height, const float* data, const TiffScale& scale)
{
  if (width <= 0 || height <= 0)
  {
    throw std::invalid_argument("tiff: image size must be positive (got " + std::to_string(width) + " x " +
                                std::to_string(height) + ")");
  }
  if (data == nullptr)
    throw std::invalid_argument("tiff: no pixel data");
  checkScale(scale.pixel_x_m, "pixel_x_m");
  checkScale(scale.pixel_y_m, "pixel_y_m");
  if (!std::isfinite(scale.x_left_m) || !std::isfinite(scale.y_top_m))
  {
    throw std::invalid_argument("tiff: the image position must be finite (got x_left_m " +
                                fullPrecisionText(scale.x_left_m) + ", y_top_m " + fullPrecisionText(scale.y_top_m) +
                                ")");
  }
  for (char c : scale.description)
  {
    const unsigned char u = static_cast<unsigned char>(c);
    if (u == 0 || u > 127)
      throw std::invalid_argument("tiff: the description must be 7-bit ASCII without NUL: \"" + scale.description +
                                  "\"");
  }

  const std::uint64_t row_bytes = 4ull * static_cast<std::uint64_t>(width);
  const std::uint64_t image_bytes = row_bytes * static_cast<std::uint64_t>(height);
  const std::uint64_t rows_per_strip =
      std::max<std::uint64_t>(1, std::min<std::uint64_t>(static_cast<std::uint64_t>(height), kStripBytes / row_bytes));
  const std::uint64_t strips = (static_cast<std::uint64_t>(height) + rows_per_strip - 1) / rows_per_strip;
  // Everything but the pixels is well under 1 MiB for any strip count that fits.
  if (image_bytes + 8 * strips + (1u << 20) > static_cast<std::uint64_t>(kMaxU32))
  {
    throw std::invalid_argument("tiff: a " + std::to_string(width) + " x " + std::to_string(height) +
                                " float image passes the 4 GiB limit of classic TIFF");
  }

  std::vector<std::uint32_t> strip_counts(strips), strip_offsets(strips, 0);
  for (std::uint64_t s = 0; s < strips; ++s)
  {
    const std::uint64_t rows =
        std::min<std::uint64_t>(rows_per_strip, static_cast<std::uint64_t>(height) - s * rows_per_strip);
    strip_counts[s] = static_cast<std::uint32_t>(rows * row_bytes);
  }

  std::vector<Entry> entries;
  entries.push_back(longs(256, {static_cast<std::uint32_t>(width)}));
  entries.push_back(longs(257, {static_cast<std::uint32_t>(height)}));
  entries.push_back(shorts(258, {32}));  // BitsPerSample
  entries.push_back(shorts(259, {1}));   // Compression: none
  entries.push_back(shorts(262, {1}));   // PhotometricInterpretation: BlackIsZero
  if (!scale.description.empty())
  {
    Entry e{270, kAscii, static_cast<std::uint32_t>(scale.description.size() + 1), {}};
    e.bytes.assign(scale.description.begin(), scale.description.end());
    e.bytes.push_back(0);
    entries.push_back(e);
  }
  const std::size_t strip_offsets_entry = entries.size();
  entries.push_back(longs(273, strip_offsets));  // StripOffsets, filled in below
  entries.push_back(shorts(277, {1}));           // SamplesPerPixel
  entries.push_back(longs(278, {static_cast<std::uint32_t>(rows_per_strip)}));
  entries.push_back(longs(279, strip_counts));  // StripByteCounts
  entries.push_back(rational(282, 0.01 / scale.pixel_x_m, "XResolution"));
  entries.push_back(rational(283, 0.01 / scale.pixel_y_m, "YResolution"));
  entries.push_back(shorts(284, {1}));                                         // PlanarConfiguration: chunky
  entries.push_back(shorts(296, {3}));                                         // ResolutionUnit: centimetre
  entries.push_back(shorts(339, {3}));                                         // SampleFormat: IEEE floating point
  entries.push_back(doubles(33550, {scale.pixel_x_m, scale.pixel_y_m, 0.0}));  // ModelPixelScaleTag
  entries.push_back(doubles(33922, {0.0, 0.0, 0.0, scale.x_left_m, scale.y_top_m, 0.0}));  // ModelTiepointTag
  // GeoKeyDirectoryTag: version 1.1.0, 3 keys (id, location 0 = value inline, count 1, value).
  entries.push_back(shorts(34735, {1, 1, 0, 3,           //
                                   1024, 0, 1, 32767,    // GTModelTypeGeoKey: user-defined (local)
                                   1025, 0, 1, 1,        // GTRasterTypeGeoKey: PixelIsArea
                                   3076, 0, 1, 9001}));  // ProjLinearUnitsGeoKey: metre

  // Layout: header, IFD, out-of-line values (each at an 8-byte boundary), strips.
  auto align8 = [](std::size_t n) { return (n + 7) & ~static_cast<std::size_t>(7); };
  const std::size_t ifd_at = 8;
  std::size_t at = align8(ifd_at + 2 + 12 * entries.size() + 4);
  std::vector<std::size_t> value_at(entries.size(), 0);
  for (std::size_t i = 0; i < entries.size(); ++i)
  {
    if (entries[i].bytes.size() > 4)
    {
      value_at[i] = at;
      at = align8(at + entries[i].bytes.size());
    }
  }
  std::size_t strip_at = at;
  for (std::uint64_t s = 0; s < strips; ++s)
  {
    strip_offsets[s] = static_cast<std::uint32_t>(strip_at);
    strip_at += strip_counts[s];
  }
  entries[strip_offsets_entry] = longs(273, strip_offsets);  // same size: the layout holds

  std::vector<std::uint8_t> out;
  out.reserve(strip_at);
  out.push_back('I');
  out.push_back('I');
  putU16(out, 42);
  putU32(out, static_cast<std::uint32_t>(ifd_at));
  putU16(out, static_cast<std::uint16_t>(entries.size()));
  for (std::size_t i = 0; i < entries.size(); ++i)
  {
    const Entry& e = entries[i];
    putU16(out, e.tag);
    putU16(out, e.type);
    putU32(out, e.count);
    if (e.bytes.size() > 4)
      putU32(out, static_cast<std::uint32_t>(value_at[i]));
    else
    {
      out.insert(out.end(), e.bytes.begin(), e.bytes.end());  // left-justified in the 4 bytes
      out.insert(out.end(), 4 - e.bytes.size(), 0);
    }
  }
  putU32(out, 0);  // no next IFD
  for (std::size_t i = 0; i < entries.size(); ++i)
  {
    if (entries[i].bytes.size() > 4)
    {
      out.resize(value_at[i], 0);
      out.insert(out.end(), entries[i].bytes.begin(), entries[i].bytes.end());
    }
  }
  out.resize(strip_offsets[0], 0);
  const std::size_t pixels = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  const std::size_t pixel_at = out.size();
  out.resize(pixel_at + 4 * pixels);
  for (std::size_t i = 0; i < pixels; ++i)
  {
    std::uint32_t bits;
    std::memcpy(&bits, data + i, sizeof bits);
    putU32At(out, pixel_at + 4 * i, bits);  // little-endian whatever the host
  }
  return out;
}

void writeFloatTiff(const std::string& path, int width, int height, const float* data, const TiffScale& scale)
{
  const std::vector<std::uint8_t> bytes = encodeFloatTiff(width, height, data, scale);
  const std::string tmp = path + ".tmp";
  try
  {
    writeFileBytes(tmp, bytes.data(), bytes.size());
  }
  catch (const InputError& e)
  {
    std::remove(tmp.c_str());
    throw InputError(path + ": " + e.what());  // the file the user knows first, then the temporary one
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0)
  {
    const std::string why = std::strerror(errno);
    std::remove(tmp.c_str());
    throw InputError(path + ": cannot rename " + tmp + " to it: " + why);
  }
}
}  // namespace scanhead
