/// \file tile_spill_file.cpp
/// \brief Batched, block-cached tile file with direct I/O where available.
#include "scanhead/energy/tile_spill_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <new>

#include "scanhead/common/errors.hpp"

namespace scanhead
{
namespace
{
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
  finishWritesQuietly();  // the writer reads the staging buffer and the descriptor
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
    finishWritesQuietly();
    other.finishWritesQuietly();  // its writer's task points at it
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
    staging_ = std::move(other.staging_);
    staging_tiles_ = other.staging_tiles_;
    runs_ = std::move(other.runs_);
    writer_ = std::move(other.writer_);
    write_error_ = std::move(other.write_error_);
    other.staging_tiles_ = 0;
    other.write_error_ = nullptr;
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
  finishWrites();  // its staging buffer is about to be reused
  if (fd_ < 0)
    open();
  std::sort(tiles.begin(), tiles.end(), [](const Pending& a, const Pending& b) { return a.offset < b.offset; });
  const std::size_t tile_floats = tile_bytes_ / sizeof(float);
  if (staging_tiles_ < tiles.size())
  {
    staging_.reset();  // before the larger one: never both
    staging_tiles_ = 0;
    staging_ = allocateAligned(tiles.size() * tile_floats);
    staging_tiles_ = tiles.size();
  }
  const std::int64_t tile = static_cast<std::int64_t>(tile_bytes_);
  runs_.clear();
  for (std::size_t k = 0; k < tiles.size(); ++k)
  {
    std::memcpy(staging_.get() + k * tile_floats, tiles[k].data, tile_bytes_);
    if (!runs_.empty() && tiles[k].offset == runs_.back().offset + static_cast<std::int64_t>(runs_.back().count) * tile)
      ++runs_.back().count;
    else
      runs_.push_back({tiles[k].offset, k, 1});
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
  if (!writer_)
    writer_ = std::make_unique<SideThread>();
  writer_->start([this, tile_floats] {
    for (const Run& run : runs_)
      transfer(true, run.offset, staging_.get() + run.first * tile_floats, run.count * tile_bytes_);
  });
  in_flight_ = true;
}

void TileSpillFile::finishWrites()
{
  if (in_flight_)
  {
    in_flight_ = false;
    try
    {
      writer_->wait();  // rethrows the writer's InputError
    }
    catch (...)
    {
      write_error_ = std::current_exception();
    }
  }
  // Sticky: the file lacks the tiles of the failed batch (their buffers were reused), so every later write or read
  // fails too instead of reading a hole; only clear() forgets it.
  if (write_error_)
    std::rethrow_exception(write_error_);
}

void TileSpillFile::finishWritesQuietly() noexcept
{
  try
  {
    finishWrites();
  }
  catch (...)
  {
    // kept in write_error_: thrown again by the next call that needs the file
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
  finishWrites();       // the block may hold tiles still on their way to the file
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
  finishWritesQuietly();
  write_error_ = nullptr;  // about tiles now forgotten
  end_ = 0;
  for (Block& b : blocks_)
    b.offset = -1;
}

std::size_t TileSpillFile::cacheBytes() const
{
  return blocks_.size() * block_bytes_ + staging_tiles_ * tile_bytes_;
}
}  // namespace scanhead
