/// \file cli_binary.cpp
/// \brief Binary CLI geometry: little-endian commands 127..132 (see cli_format.hpp).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>

#include "cli_internal.hpp"
#include "scanhead/common/errors.hpp"

namespace scanhead
{
namespace cli
{
namespace
{
enum Command : std::uint16_t
{
  kLayerLong = 127,
  kLayerShort = 128,
  kPolylineShort = 129,
  kPolylineLong = 130,
  kHatchesShort = 131,
  kHatchesLong = 132
};

class BinaryGeometry
{
public:
  BinaryGeometry(const std::string& bytes, const Header& header, const std::string& source, JobBuilder& builder)
    : data_(reinterpret_cast<const unsigned char*>(bytes.data()))
    , size_(bytes.size())
    , pos_(std::min(header.geometry_offset, bytes.size()))
    , uint_bytes_(header.aligned ? 4 : 2)
    , source_(source)
    , b_(builder)
  {
  }

  void run()
  {
    while (pos_ < size_)
    {
      const std::size_t at = pos_;
      need(uint_bytes_, "a command index");
      const std::uint16_t cmd = uintParam();
      switch (cmd)
      {
        case kLayerLong:
          need(4, "the real z of 'start layer long'");
          real("z");
          b_.startLayer();
          break;
        case kLayerShort:
          need(uint_bytes_, "the uint z of 'start layer short'");
          uintParam();
          b_.startLayer();
          break;
        case kPolylineShort:
          polylineShort(at);
          break;
        case kPolylineLong:
          polylineLong(at);
          break;
        case kHatchesShort:
          hatchesShort(at);
          break;
        case kHatchesLong:
          hatchesLong(at);
          break;
        default:
          fail(at, "unknown command index " + std::to_string(cmd) +
                       " (expected 127..132: start layer long/short, polyline short/long, hatches short/long)");
      }
    }
  }

private:
  [[noreturn]] void fail(std::size_t offset, const std::string& what) const
  {
    throw InputError(source_ + ": byte offset " + std::to_string(offset) + ": " + what);
  }

  std::size_t left() const { return size_ - pos_; }

  void need(std::size_t bytes, const std::string& what) const
  {
    if (left() < bytes)
      fail(pos_, "truncated: expected " + what + " (" + std::to_string(bytes) + " bytes), but the file ends " +
                     std::to_string(left()) + " bytes later");
  }

  /// \brief The 8n bytes, 16n bytes, ... an item count announces, checked before anything is
  /// reserved.
  void needItems(std::size_t at, long long n, std::size_t bytes_per_item, const char* what) const
  {
    if (n < 0)
      fail(at, std::string("negative count n = ") + std::to_string(n) + " of " + what);
    const unsigned long long bytes = static_cast<unsigned long long>(n) * bytes_per_item;  // n < 2^31: no overflow
    if (bytes > left())
      fail(at, "count n = " + std::to_string(n) + " of " + what + " needs " + std::to_string(bytes) +
                   " bytes, but only " + std::to_string(left()) + " remain (truncated file or wrong count)");
  }

  std::uint16_t u16()
  {
    const unsigned char* q = data_ + pos_;
    pos_ += 2;
    return static_cast<std::uint16_t>(q[0] | (q[1] << 8));
  }

  std::uint32_t u32()
  {
    const unsigned char* q = data_ + pos_;
    pos_ += 4;
    return static_cast<std::uint32_t>(q[0]) | (static_cast<std::uint32_t>(q[1]) << 8) |
           (static_cast<std::uint32_t>(q[2]) << 16) | (static_cast<std::uint32_t>(q[3]) << 24);
  }

  /// \brief A uint parameter (or command index), followed by 2 padding bytes with $$ALIGN.
  std::uint16_t uintParam()
  {
    const std::uint16_t v = u16();
    pos_ += uint_bytes_ - 2;
    return v;
  }

  std::int32_t i32()
  {
    const std::uint32_t u = u32();
    std::int32_t v;
    std::memcpy(&v, &u, sizeof v);
    return v;
  }

  double real(const char* what)
  {
    const std::size_t at = pos_;
    const std::uint32_t u = u32();
    float v;
    std::memcpy(&v, &u, sizeof v);
    if (!std::isfinite(v))
      fail(at, std::string("expected a finite real for ") + what + ", got a NaN or infinity");
    return static_cast<double>(v);
  }

  void requireLayer(std::size_t at, const char* what) const
  {
    if (!b_.inLayer())
      fail(at, std::string(what) + " before any start-layer command");
  }

  void checkDir(std::size_t at, long long dir) const
  {
    if (dir < 0 || dir > 2)
      fail(at, "expected polyline dir 0 (clockwise), 1 (counter-clockwise) or 2 (open), got " + std::to_string(dir));
  }

  void polylineShort(std::size_t at)
  {
    requireLayer(at, "polyline short (129)");
    need(3 * uint_bytes_, "id, dir, n of 'polyline short'");
    uintParam();
    const std::size_t dir_at = pos_;
    checkDir(dir_at, uintParam());
    const std::size_t n_at = pos_;
    const std::uint16_t n = uintParam();
    needItems(n_at, n, 4, "points of 'polyline short'");
    b_.beginMark(n, PolylineRole::Contour);
    for (std::uint16_t i = 0; i < n; ++i)
    {
      const double x = u16();
      const double y = u16();
      b_.addPoint(x, y);
    }
    b_.endMark();
  }

  void polylineLong(std::size_t at)
  {
    requireLayer(at, "polyline long (130)");
    need(12, "int id, dir, n of 'polyline long'");
    i32();
    const std::size_t dir_at = pos_;
    checkDir(dir_at, i32());
    const std::size_t n_at = pos_;
    const std::int32_t n = i32();
    needItems(n_at, n, 8, "points of 'polyline long'");
    b_.beginMark(static_cast<std::size_t>(n), PolylineRole::Contour);
    for (std::int32_t i = 0; i < n; ++i)
    {
      const double x = real("x of a 'polyline long' point");
      const double y = real("y of a 'polyline long' point");
      b_.addPoint(x, y);
    }
    b_.endMark();
  }

  void hatchesShort(std::size_t at)
  {
    requireLayer(at, "hatches short (131)");
    need(2 * uint_bytes_, "id, n of 'hatches short'");
    uintParam();
    const std::size_t n_at = pos_;
    const std::uint16_t n = uintParam();
    needItems(n_at, n, 8, "hatches of 'hatches short'");
    for (std::uint16_t i = 0; i < n; ++i)
    {
      const double xs = u16();
      const double ys = u16();
      const double xe = u16();
      const double ye = u16();
      hatch(xs, ys, xe, ye);
    }
  }

  void hatchesLong(std::size_t at)
  {
    requireLayer(at, "hatches long (132)");
    need(8, "int id, n of 'hatches long'");
    i32();
    const std::size_t n_at = pos_;
    const std::int32_t n = i32();
    needItems(n_at, n, 16, "hatches of 'hatches long'");
    for (std::int32_t i = 0; i < n; ++i)
    {
      const double xs = real("start x of a hatch");
      const double ys = real("start y of a hatch");
      const double xe = real("end x of a hatch");
      const double ye = real("end y of a hatch");
      hatch(xs, ys, xe, ye);
    }
  }

  void hatch(double xs, double ys, double xe, double ye)
  {
    b_.beginMark(2, PolylineRole::Hatch);
    b_.addPoint(xs, ys);
    b_.addPoint(xe, ye);
    b_.endMark();
  }

  const unsigned char* data_;
  std::size_t size_;
  std::size_t pos_;
  std::size_t uint_bytes_;
  const std::string& source_;
  JobBuilder& b_;
};
}  // namespace

void parseBinaryGeometry(const std::string& bytes, const Header& header, const std::string& source, JobBuilder& builder)
{
  BinaryGeometry(bytes, header, source, builder).run();
}
}  // namespace cli
}  // namespace scanhead
