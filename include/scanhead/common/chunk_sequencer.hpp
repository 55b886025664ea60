/// \file chunk_sequencer.hpp
/// \brief Where each chunk of a stream stands against the samples already taken: the one place
/// that detects and counts gaps, overlaps and reordering, for every consumer of a stream.
///
/// Samples carry global indices (chunk.hpp). A consumer takes each index once, in increasing
/// order: the samples of a chunk whose indices were already taken (a duplicate, an overlap, a
/// chunk that arrives after its successor) are skipped, and the indices between the last sample
/// taken and the first new one are missing (a gap). Since the indices inside a chunk are
/// consecutive, one admission per chunk classifies every sample exactly as a per-sample check would.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>

namespace scanhead
{
/// \brief What a chunk brings: its samples [skip, size) are new; before them, missing samples.
struct ChunkAdmission
{
  std::size_t skip = 0;       ///< leading samples already taken (skipped)
  std::uint64_t missing = 0;  ///< indices lost before samples[skip] (counted from index 0 at the start)
  /// \brief The new samples do not continue a stream already \p started (the sequencer's started()
  /// before admit): a consumer must not join its path, filters or deposit across this point.
  bool broken(bool started) const { return started && missing > 0; }
};

class ChunkSequencer
{
public:
  /// \brief Forgets everything (a new job).
  void reset() { *this = ChunkSequencer(); }

  /// \brief Admits the chunk of \p size samples starting at \p first_index, takes its new samples
  /// and counts what was skipped and missing.
  ChunkAdmission admit(std::uint64_t first_index, std::size_t size)
  {
    ChunkAdmission a;
    if (size == 0)
      return a;
    if (first_index < next_)
    {
      a.skip = static_cast<std::size_t>(std::min<std::uint64_t>(size, next_ - first_index));
      repeated_ += a.skip;
      if (a.skip < size)
        ++reorders_;  // partly new: an overlap; entirely old chunks are duplicates or late
      else
        ++late_chunks_;
    }
    const std::uint64_t first_new = first_index + a.skip;
    if (a.skip == size)
      return a;  // nothing new
    a.missing = first_new - next_;
    if (a.missing > 0)
      ++gaps_;
    missing_ += a.missing;
    taken_ += size - a.skip;
    next_ = first_index + size;
    started_ = true;
    return a;
  }

  bool started() const { return started_; }
  std::uint64_t next() const { return next_; }               ///< one past the last index taken
  std::uint64_t taken() const { return taken_; }             ///< samples taken
  std::uint64_t missing() const { return missing_; }         ///< samples lost in gaps (and before the first)
  std::uint64_t repeated() const { return repeated_; }       ///< samples skipped as already taken
  std::uint64_t gaps() const { return gaps_; }               ///< gaps seen
  std::uint64_t lateChunks() const { return late_chunks_; }  ///< chunks with nothing new
  std::uint64_t overlaps() const { return reorders_; }       ///< chunks that were partly old

private:
  bool started_ = false;
  std::uint64_t next_ = 0;
  std::uint64_t taken_ = 0, missing_ = 0, repeated_ = 0, gaps_ = 0, late_chunks_ = 0, reorders_ = 0;
};
}  // namespace scanhead
