/// \file staged_folder.hpp
/// \brief A folder written under a name of its own beside its target and published by rename only
/// when complete, so the target is always either the previous folder or the new one, whole.
///
/// The staging folder is `.<name>.staging.<pid>.<16 hex digits>` beside the target: unique per run
/// (two runs never share or delete each other's), hidden, and on the target's file system (a rename,
/// not a copy). publish() swaps it with the target by renameat2(RENAME_EXCHANGE) (ext4, xfs, btrfs,
/// tmpfs): the target path names the previous folder until the instant it names the new one. Where
/// the file system has no exchange (NFS, old kernels) the previous folder is renamed aside to
/// `.<name>.previous.<pid>.<hex>` first, then the new one into place, then the previous one deleted;
/// a failure between the two renames puts the previous folder back.
///
/// Cleanup: the destructor removes an unpublished staging folder (the error path of the caller, and
/// a signal turned into an exception by common/stop_request). A run killed outright (SIGKILL, power
/// loss) leaves its staging folder: the next writer of the same target, holding the target's
/// FolderLock, knows no one else is writing it, so removeStale() deletes every staging folder of the
/// target and restores a previous folder a killed run had renamed aside.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "scanhead/common/folder_lock.hpp"

namespace scanhead
{
class StagedFolder
{
public:
  /// \brief Creates the staging folder beside lock.folder().
  /// \pre \p lock is held for the life of this object
  /// \throws InputError if it cannot be created (the message says why: "no space left on device")
  explicit StagedFolder(const FolderLock& lock);
  /// \brief Removes the staging folder (whatever is in it) unless publish() succeeded.
  ~StagedFolder();
  StagedFolder(const StagedFolder&) = delete;
  StagedFolder& operator=(const StagedFolder&) = delete;

  /// \brief The staging folder (absolute).
  const std::filesystem::path& path() const { return path_; }
  /// \brief The target (absolute).
  const std::filesystem::path& target() const { return target_; }

  /// \brief Makes the staging folder the target, replacing a previous target folder (which the
  /// caller has checked may be replaced) and then deleting it.
  /// \throws InputError if the renames fail (the previous folder is then still the target)
  void publish();

  /// \brief A write failure's message for the user: paths in the staging folder become the target's
  /// ("<target>/energy_map.png"), and a full disk (the message holds strerror(ENOSPC) or
  /// strerror(EDQUOT), or the file system is full now: a plot script's failure) opens with
  /// "no space left on device writing <file>", the file the message names.
  std::string explain(const std::string& message) const;

  /// \brief Removes what killed writers of lock.folder() left beside it: their staging folders, and
  /// the legacy `.<name>.partial`; a previous folder renamed aside is put back if the target is
  /// missing (else deleted).
  /// \pre \p lock is held (so no other run is writing any of them)
  /// \return the paths removed or restored
  static std::vector<std::string> removeStale(const FolderLock& lock);

  /// \brief Whether \p name is a staging (or aside) folder name of the target named \p target_name.
  static bool isStagingName(const std::string& name, const std::string& target_name);

private:
  std::filesystem::path target_;
  std::filesystem::path path_;
  bool published_ = false;
};

/// \brief Whether the file system holding \p path has no room left for this process (blocks or
/// inodes below 64 KiB / 16 inodes, the reserved blocks counted for root only), as after a
/// failed write.
bool fileSystemFull(const std::filesystem::path& path);
}  // namespace scanhead
