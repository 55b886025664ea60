/// \file tile_spill_file.cpp
/// \brief Batched, block-cached tile file with direct I/O where available.
#include "scanhead/energy/tile_spill_file.hpp"

#include <fcntl.h>
#include <sys/uio.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <new>

#include "scanhead/common/errors.hpp"

namespace scanhead
{
namespace
{
constexpr std::size_t kMaxRunTiles = 64;  // tiles in one pwritev (well under IOV_MAX = 1024)

std::string ioError(const std::string& what, const std::string& dir)
{
  return "energy map: cannot " + what + " the tile spill file in " + dir + " (" + std::strerror(errno) +
         "): check energy.spill_dir (or TMPDIR) and its free space, or raise energy.tile_cache_bytes";
}
}  // namespace

void AlignedFree::operator()(float* p) const
{
  std::free(p);
}

AlignedFloats allocateAligned(std::size_t count)
{
  const std::size_t bytes =
      (count * sizeof(float) + TileSpillFile::kAlignment - 1) / TileSpillFile::kAlignment * TileSpillFile::kAlignment;
  void* p = std::aligned_alloc(TileSpillFile::kAlignment, std::max(bytes, TileSpillFile::kAlignment));
  if (p == nullptr)
    throw std::bad_alloc();
  return AlignedFloats(static_cast<float*>(p));
}

TileSpillFile::TileSpillFile(std::size_t tile_bytes, std::size_t block_tiles, std::size_t blocks, std::string dir)
  : tile_bytes_(tile_bytes)
  , block_bytes_(tile_bytes * std::max<std::size_t>(1, block_tiles))
  , max_blocks_(std::max<std::size_t>(1, blocks))
  , dir_(std::move(dir))
{
}

TileSpillFile::~TileSpillFile()
{
  if (fd_ >= 0)
    ::close(fd_);
}

TileSpillFile::TileSpillFile(TileSpillFile&& other) noexcept
{
  *this = std::move(other);
}

TileSpillFile& TileSpillFile::operator=(TileSpillFile&& other) noexcept
{
  if (this != &other)
  {
    if (fd_ >= 0)
      ::close(fd_);
    tile_bytes_ = other.tile_bytes_;
    block_bytes_ = other.block_bytes_;
    max_blocks_ = other.max_blocks_;
    dir_ = std::move(other.dir_);
    fd_ = other.fd_;
    direct_ = other.direct_;
    end_ = other.end_;
    blocks_ = std::move(other.blocks_);
    clock_ = other.clock_;
    block_reads_ = other.block_reads_;
    other.fd_ = -1;
    other.end_ = 0;
    other.blocks_.clear();
  }
  return *this;
}

std::string TileSpillFile::folder() const
{
  const char* tmpdir = std::getenv("TMPDIR");
  return !dir_.empty() ? dir_ : tmpdir != nullptr && *tmpdir != '\0' ? tmpdir : "/tmp";
}

void TileSpillFile::open()
{
  const std::string dir = folder();
  std::string path = dir + "/scanhead_tiles_XXXXXX";
  fd_ = ::mkstemp(path.data());
  if (fd_ < 0)
    throw InputError(ioError("create", dir));
  ::unlink(path.c_str());  // the space is freed when the file is closed, even by a crash
  const int flags = ::fcntl(fd_, F_GETFL);
  direct_ = flags >= 0 && ::fcntl(fd_, F_SETFL, flags | O_DIRECT) == 0;  // else through the page cache
}

std::int64_t TileSpillFile::allocate()
{
  const std::int64_t offset = end_;
  end_ += static_cast<std::int64_t>(tile_bytes_);
  return offset;
}

void TileSpillFile::transfer(bool writing, std::int64_t offset, void* data, std::size_t bytes)
{
  char* p = static_cast<char*>(data);
  while (bytes > 0)
  {
    const ssize_t n = writing ? ::pwrite(fd_, p, bytes, offset) : ::pread(fd_, p, bytes, offset);
    if (n < 0 && errno == EINTR)
      continue;
    if (n < 0 && errno == EINVAL && direct_)
    {
      // The file system took O_DIRECT but refuses this transfer: through the page cache from now on.
      ::fcntl(fd_, F_SETFL, ::fcntl(fd_, F_GETFL) & ~O_DIRECT);
      direct_ = false;
      continue;
    }
    if (n <= 0)
    {
      if (n == 0)
        errno = EIO;  // a read past what was written, or a write that wrote nothing
      throw InputError(ioError(writing ? "write" : "read", folder()));
    }
    p += n;
    offset += n;
    bytes -= static_cast<std::size_t>(n);
  }
}

void TileSpillFile::write(std::vector<Pending>& tiles)
{
  if (tiles.empty())
    return;
  if (fd_ < 0)
    open();
  std::sort(tiles.begin(), tiles.end(), [](const Pending& a, const Pending& b) { return a.offset < b.offset; });
  const std::int64_t tile = static_cast<std::int64_t>(tile_bytes_);
  std::vector<iovec> iov;
  iov.reserve(kMaxRunTiles);
  for (std::size_t i = 0; i < tiles.size();)
  {
    // A run of consecutive offsets: one call (a partial or refused one is finished tile by tile).
    std::size_t j = i + 1;
    while (j < tiles.size() && j - i < kMaxRunTiles && tiles[j].offset == tiles[j - 1].offset + tile)
      ++j;
    iov.clear();
    for (std::size_t k = i; k < j; ++k)
      iov.push_back({const_cast<float*>(tiles[k].data), tile_bytes_});
    const ssize_t want = static_cast<ssize_t>((j - i) * tile_bytes_);
    ssize_t n = ::pwritev(fd_, iov.data(), static_cast<int>(iov.size()), tiles[i].offset);
    if (n != want)
    {
      const std::size_t done = n > 0 ? static_cast<std::size_t>(n) / tile_bytes_ : 0;
      for (std::size_t k = i + done; k < j; ++k)
        transfer(true, tiles[k].offset, const_cast<float*>(tiles[k].data), tile_bytes_);
    }
    i = j;
  }
  // Cached blocks stay equal to the file.
  for (Block& b : blocks_)
  {
    if (b.offset < 0)
      continue;
    for (const Pending& t : tiles)
      if (t.offset >= b.offset && t.offset + tile <= b.offset + static_cast<std::int64_t>(b.bytes))
        std::memcpy(b.data.get() + (t.offset - b.offset) / static_cast<std::int64_t>(sizeof(float)), t.data,
                    tile_bytes_);
  }
}

TileSpillFile::Block& TileSpillFile::blockFor(std::int64_t tile_offset)
{
  const std::int64_t block_bytes = static_cast<std::int64_t>(block_bytes_);
  const std::int64_t start = tile_offset / block_bytes * block_bytes;
  Block* victim = nullptr;
  for (Block& b : blocks_)
  {
    if (b.offset == start &&
        tile_offset + static_cast<std::int64_t>(tile_bytes_) <= start + static_cast<std::int64_t>(b.bytes))
    {
      b.last_use = ++clock_;
      return b;
    }
    if (b.offset == start)
      victim = &b;  // read while the file ended before this tile: read it again
  }
  if (victim == nullptr && blocks_.size() < max_blocks_)
  {
    blocks_.emplace_back();
    blocks_.back().data = allocateAligned(block_bytes_ / sizeof(float));
    victim = &blocks_.back();
  }
  if (victim == nullptr)
    victim = &*std::min_element(blocks_.begin(), blocks_.end(),
                                [](const Block& a, const Block& b) { return a.last_use < b.last_use; });
  victim->offset = -1;  // empty until the read succeeds
  const std::size_t bytes = static_cast<std::size_t>(std::min(block_bytes, end_ - start));
  transfer(false, start, victim->data.get(), bytes);
  ++block_reads_;
  victim->offset = start;
  victim->bytes = bytes;
  victim->last_use = ++clock_;
  return *victim;
}

void TileSpillFile::read(std::int64_t offset, float* to)
{
  const Block& b = blockFor(offset);
  std::memcpy(to, b.data.get() + (offset - b.offset) / static_cast<std::int64_t>(sizeof(float)), tile_bytes_);
}

void TileSpillFile::clear()
{
  end_ = 0;
  for (Block& b : blocks_)
    b.offset = -1;
}

std::size_t TileSpillFile::cacheBytes() const
{
  return blocks_.size() * block_bytes_;
}
}  // namespace scanhead
