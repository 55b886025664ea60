/// \file folder_lock.hpp
/// \brief An exclusive lock on an output folder that may not exist yet: flock(2) on the file
/// `.<name>.lock` beside it, which also names the holder (pid, host, program, start time).
///
/// Why flock on a sibling file: the lock must exist before the folder does (a run takes it before
/// its chain starts) and must outlive the folder's replacement (the folder is renamed away). The
/// kernel drops a flock when its last descriptor closes, so a run that dies, even by SIGKILL,
/// releases it; the descriptor is close-on-exec, so a plot process started meanwhile does not keep
/// it. Taking it never waits: a second writer fails at once with a FolderBusyError naming the
/// holder. A lock file left by a killed run is simply taken over.
///
/// Releasing removes the lock file while still holding the lock; a taker checks, once it holds the
/// lock, that its descriptor is still the file on that path (else it retries), so two runs can
/// never both believe they hold it. flock is local to a host (on NFS it is emulated by fcntl locks,
/// which Linux also releases on death).
#pragma once

#include <filesystem>
#include <string>

#include "scanhead/common/errors.hpp"

namespace scanhead
{
/// \brief Another process holds the lock: the message names it and what to do.
class FolderBusyError : public InputError
{
public:
  using InputError::InputError;
};

class FolderLock
{
public:
  /// \brief Takes the lock of \p folder now (creating the folder's parent if needed; a parent
  /// created here is removed again on release if the folder was never written).
  /// \throws FolderBusyError "<folder>: being written by <program> (pid P on host H since T);
  /// wait for it to end or choose another output folder" if another process holds it
  /// \throws InputError if the parent or the lock file cannot be created
  explicit FolderLock(const std::string& folder);
  /// \brief Releases the lock (removes the lock file, then closes it).
  ~FolderLock();
  FolderLock(FolderLock&& other) noexcept;
  FolderLock& operator=(FolderLock&& other) noexcept;
  FolderLock(const FolderLock&) = delete;
  FolderLock& operator=(const FolderLock&) = delete;

  /// \brief The locked folder: absolute and normalised (no trailing separator).
  const std::filesystem::path& folder() const { return folder_; }

  /// \brief `<parent>/.<name>.lock`, the lock file of \p folder (absolute, normalised).
  static std::filesystem::path lockFileOf(const std::filesystem::path& folder);

  /// \brief What the lock file of \p folder says about its holder (pid, host, program, start),
  /// one line, or "" if there is no lock file or it is empty. For messages and tests.
  static std::string holderOf(const std::filesystem::path& folder);

private:
  void release() noexcept;

  std::filesystem::path folder_;
  std::filesystem::path lock_file_;  ///< lockFileOf(folder_), resolved once
  std::filesystem::path created_;    ///< the outermost parent folder this lock created, or empty
  int fd_ = -1;
};
}  // namespace scanhead
