/// \file tile_spill_file.hpp
/// \brief The temporary file behind TiledEnergyMap's bounded cache: tiles written in batches, read back through a
/// small cache of file blocks, with direct I/O (no page cache) where the file system allows it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "scanhead/common/side_thread.hpp"

namespace scanhead
{
/// \brief Frees memory of allocateAligned().
struct AlignedFree
{
  void operator()(float* p) const;
};
/// \brief Floats aligned to TileSpillFile::kAlignment (direct I/O reads and writes straight from such buffers).
using AlignedFloats = std::unique_ptr<float[], AlignedFree>;
/// \brief \p count floats aligned to TileSpillFile::kAlignment. \throws std::bad_alloc
AlignedFloats allocateAligned(std::size_t count);

/// \brief Fixed-size tiles of floats kept in an unlinked temporary file.
///
/// Why direct I/O: a spilled tile is written once and read back once or twice (the end-of-run passes), so the page
/// cache only costs: on the 2-core development VM, writing 5.4 GB through the page cache takes 17 s of system time
/// (316 MB/s), and 1 MiB direct writes reach 1.1 GB/s with 0.2 s of system time (`dd`, measured); a spilled THESIS
/// layer writes 5.3 GB. Direct I/O is slow for small scattered reads (~80 µs a 16 KiB read), so reads go through a
/// cache of whole file blocks (block_tiles tiles, one read each): the map writes each batch of evicted tiles in tile
/// order at consecutive offsets, so a pass over the map in tile order, or along the track, reads the file nearly in
/// order. Where the file system refuses O_DIRECT the same calls go through the page cache.
///
/// Cached blocks always equal the file: a write updates the cached copy of every tile it covers. Values never depend
/// on direct I/O or the cache: a tile reads back the bytes written.
///
/// Writes run in the background: write() copies the batch into a staging buffer and returns while a writer thread
/// sends it to the file (on the THESIS layer the map's thread waited ~5 s for 5.3 GB of direct writes). One batch is
/// in flight at most: the next write() and any read of the file wait for it first, and an error of the background
/// write is thrown there (or by finishWrites()), and by every later write or read (the file lacks those tiles). The
/// staging buffer holds the largest batch (cacheBytes() counts it).
class TileSpillFile
{
public:
  static constexpr std::size_t kAlignment = 4096;  ///< of buffers, offsets and lengths under direct I/O

  /// \param[in] tile_bytes  bytes per tile (a multiple of kAlignment)
  /// \param[in] block_tiles tiles per cached block (≥ 1)
  /// \param[in] blocks      cached blocks at most (≥ 1)
  /// \param[in] dir         folder of the file; "": $TMPDIR, else /tmp (created at the first write)
  TileSpillFile(std::size_t tile_bytes, std::size_t block_tiles, std::size_t blocks, std::string dir);
  TileSpillFile() = default;  ///< no tiles (a moved-from map's)
  ~TileSpillFile();
  TileSpillFile(TileSpillFile&& other) noexcept;
  TileSpillFile& operator=(TileSpillFile&& other) noexcept;
  TileSpillFile(const TileSpillFile&) = delete;
  TileSpillFile& operator=(const TileSpillFile&) = delete;

  /// \brief A tile's place at the end of the file (written by write()).
  std::int64_t allocate();
  /// \brief A tile to write: its offset from allocate() and its kAlignment-aligned data.
  struct Pending
  {
    std::int64_t offset = 0;
    const float* data = nullptr;
  };
  /// \brief Writes the tiles (sorted here by offset; consecutive ones in one call), in the background: \p tiles' data
  /// may be reused as soon as this returns.
  /// \throws InputError naming the folder if the file cannot be created, or if the previous write failed
  void write(std::vector<Pending>& tiles);
  /// \brief Waits for the write in flight, if any. \throws InputError naming the folder if it failed
  void finishWrites();
  /// \brief The tile at \p offset (written before) into \p to (any alignment), through the block cache.
  /// \throws InputError naming the folder if the file cannot be read
  void read(std::int64_t offset, float* to);
  /// \brief Forgets every tile (the file and its space are reused from offset 0).
  void clear();

  std::int64_t bytes() const { return end_; }              ///< file length in use
  std::size_t blockBytes() const { return block_bytes_; }  ///< bytes per cached block
  /// \brief Offset of the block holding \p offset.
  std::int64_t blockStart(std::int64_t offset) const
  {
    return offset / static_cast<std::int64_t>(block_bytes_) * static_cast<std::int64_t>(block_bytes_);
  }
  bool direct() const { return direct_; }                    ///< whether the file is opened with O_DIRECT
  std::size_t cacheBytes() const;                            ///< memory the cached blocks hold
  std::uint64_t blockReads() const { return block_reads_; }  ///< reads of the file (cost measure)

private:
  struct Block
  {
    std::int64_t offset = -1;  ///< file offset of its first byte (-1: empty)
    std::size_t bytes = 0;     ///< bytes read (the file may end inside the block)
    std::uint64_t last_use = 0;
    AlignedFloats data;
  };
  std::string folder() const;  ///< dir, else $TMPDIR, else /tmp
  void open();
  /// \brief pwrite or pread of all \p bytes (retried on EINTR; O_DIRECT dropped if a transfer is refused with it).
  void transfer(bool writing, std::int64_t offset, void* data, std::size_t bytes);
  Block& blockFor(std::int64_t tile_offset);
  void finishWritesQuietly() noexcept;  ///< finishWrites() keeping its error for the next call (destructor, moves)

  std::size_t tile_bytes_ = 0, block_bytes_ = 0, max_blocks_ = 1;
  std::string dir_;
  int fd_ = -1;
  bool direct_ = false;
  std::int64_t end_ = 0;
  std::vector<Block> blocks_;
  std::uint64_t clock_ = 0, block_reads_ = 0;
  /// A run of consecutive file tiles in the staging buffer: one write.
  struct Run
  {
    std::int64_t offset = 0;
    std::size_t first = 0, count = 0;  ///< staging tiles
  };
  AlignedFloats staging_;  ///< the batch in flight, in offset order
  std::size_t staging_tiles_ = 0;
  std::vector<Run> runs_;
  std::unique_ptr<SideThread> writer_;  ///< created at the first write
  bool in_flight_ = false;
  std::exception_ptr write_error_;  ///< of a failed background write (sticky until clear())
};
}  // namespace scanhead
