/// \file staged_folder.cpp
#include "scanhead/common/staged_folder.hpp"

#include <errno.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <sys/statvfs.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <cctype>
#include <cstdio>
#include <cstring>
#include <random>
#include <system_error>

#include "scanhead/common/errors.hpp"
#include "scanhead/common/text_file.hpp"

namespace scanhead
{
namespace fs = std::filesystem;

namespace
{
/// "<pid>.<16 hex digits>": the pid for a reader, the random part so that a pid reused (or two
/// threads of one process) never meets an earlier name.
std::string uniqueSuffix()
{
  std::random_device device;
  const std::uint64_t bits = (static_cast<std::uint64_t>(device()) << 32) ^ device();
  char hex[17];
  std::snprintf(hex, sizeof(hex), "%016llx", static_cast<unsigned long long>(bits));
  return std::to_string(getpid()) + "." + hex;
}

bool isSuffix(const std::string& text)
{
  const std::size_t dot = text.find('.');
  if (dot == 0 || dot == std::string::npos || text.size() != dot + 17)
    return false;
  for (std::size_t i = 0; i < dot; ++i)
    if (text[i] < '0' || text[i] > '9')
      return false;
  for (std::size_t i = dot + 1; i < text.size(); ++i)
    if (!std::isxdigit(static_cast<unsigned char>(text[i])))
      return false;
  return true;
}

std::string stagingPrefix(const std::string& target_name)
{
  return "." + target_name + ".staging.";
}

std::string asidePrefix(const std::string& target_name)
{
  return "." + target_name + ".previous.";
}

bool startsWith(const std::string& text, const std::string& prefix)
{
  return text.compare(0, prefix.size(), prefix) == 0;
}

/// renameat2(RENAME_EXCHANGE): both names must exist; they swap in one step.
int exchange(const fs::path& a, const fs::path& b)
{
#ifdef RENAME_EXCHANGE
  return renameat2(AT_FDCWD, a.c_str(), AT_FDCWD, b.c_str(), RENAME_EXCHANGE);
#else
  return static_cast<int>(syscall(SYS_renameat2, AT_FDCWD, a.c_str(), AT_FDCWD, b.c_str(), 1u << 1));
#endif
}
}  // namespace

bool fileSystemFull(const fs::path& path)
{
  struct statvfs s = {};
  if (statvfs(path.c_str(), &s) != 0)
    return false;
  const bool root = geteuid() == 0;  // root may use the blocks reserved for it
  const double free_bytes = static_cast<double>(root ? s.f_bfree : s.f_bavail) * static_cast<double>(s.f_frsize);
  const unsigned long free_inodes = root ? s.f_ffree : s.f_favail;
  return free_bytes < 65536.0 || (s.f_files > 0 && free_inodes < 16);
}

bool StagedFolder::isStagingName(const std::string& name, const std::string& target_name)
{
  for (const std::string& prefix : {stagingPrefix(target_name), asidePrefix(target_name)})
    if (startsWith(name, prefix) && isSuffix(name.substr(prefix.size())))
      return true;
  return false;
}

StagedFolder::StagedFolder(const FolderLock& lock)
  : target_(lock.folder())
{
  const fs::path parent = target_.parent_path();
  for (int attempt = 0;; ++attempt)
  {
    path_ = parent / (stagingPrefix(target_.filename().string()) + uniqueSuffix());
    if (::mkdir(path_.c_str(), 0777) == 0)
      return;
    const int error = errno;
    if (error != EEXIST || attempt >= 10)
    {
      path_.clear();
      const std::string why =
          error == ENOSPC || fileSystemFull(parent) ? "no space left on device" : std::strerror(error);
      throw InputError(target_.string() + ": cannot create its staging folder in " + parent.string() + " (" + why +
                       ")");
    }
  }
}

StagedFolder::~StagedFolder()
{
  if (published_ || path_.empty())
    return;
  std::error_code ec;
  // Twice: a plot process stopped just before may have created a file during the first pass.
  if (fs::remove_all(path_, ec) == static_cast<std::uintmax_t>(-1) || fs::exists(path_, ec))
    fs::remove_all(path_, ec);
}

void StagedFolder::publish()
{
  std::error_code ec;
  // No target (or an empty folder): a plain rename.
  if (::rename(path_.c_str(), target_.c_str()) == 0)
  {
    published_ = true;
    return;
  }
  if (errno != EEXIST && errno != ENOTEMPTY)
    throw InputError(target_.string() + ": cannot rename the new results into place (" + std::strerror(errno) + ")");
  // Swap: the staging name now holds the previous folder, which goes.
  if (exchange(path_, target_) == 0)
  {
    published_ = true;
    fs::remove_all(path_, ec);  // if this fails, the next writer's removeStale() deletes it
    return;
  }
  if (errno != EINVAL && errno != ENOSYS && errno != EOPNOTSUPP)
    throw InputError(target_.string() + ": cannot exchange it with the new results (" + std::strerror(errno) + ")");
  // No exchange on this file system: the previous folder aside, the new one in, the previous gone.
  const fs::path aside = target_.parent_path() / (asidePrefix(target_.filename().string()) + uniqueSuffix());
  if (::rename(target_.c_str(), aside.c_str()) != 0)
    throw InputError(target_.string() + ": cannot move the previous results aside (" + std::strerror(errno) + ")");
  if (::rename(path_.c_str(), target_.c_str()) != 0)
  {
    const std::string why = std::strerror(errno);
    if (::rename(aside.c_str(), target_.c_str()) != 0)  // the previous results back in place
      throw InputError(target_.string() + ": cannot rename the new results into place (" + why +
                       "); the previous results are in " + aside.string() + " (the next run puts them back)");
    throw InputError(target_.string() + ": cannot rename the new results into place (" + why + ")");
  }
  published_ = true;
  fs::remove_all(aside, ec);
}

std::string StagedFolder::explain(const std::string& message) const
{
  std::string text = message;
  if (!path_.empty())
    replaceAll(text, path_.string(), target_.string());
  const bool full = text.find(std::strerror(ENOSPC)) != std::string::npos ||
                    text.find(std::strerror(EDQUOT)) != std::string::npos || fileSystemFull(target_.parent_path());
  if (!full)
    return text;
  // The file the message names, else the folder.
  std::string file = target_.string();
  const std::size_t at = text.find(target_.string() + "/");
  if (at != std::string::npos)
    file = text.substr(at, text.find_first_of(" '\":;,()", at) - at);
  return "no space left on device writing " + file + " (" + text + ")";
}

std::vector<std::string> StagedFolder::removeStale(const FolderLock& lock)
{
  const fs::path target = lock.folder();
  const std::string name = target.filename().string();
  std::vector<std::string> done;
  std::vector<fs::path> stale;  // collected first: the loop below renames and removes entries
  std::error_code ec;
  for (fs::directory_iterator it(target.parent_path(), ec), end; !ec && it != end; it.increment(ec))
  {
    const std::string entry = it->path().filename().string();
    if (entry == "." + name + ".partial" || isStagingName(entry, name))
      stale.push_back(it->path());
  }
  for (const fs::path& path : stale)
  {
    // A previous folder set aside by a run killed before its new one was in place: put it back.
    if (startsWith(path.filename().string(), asidePrefix(name)) && !fs::exists(target, ec) &&
        ::rename(path.c_str(), target.c_str()) == 0)
    {
      done.push_back(path.string() + " (restored as " + target.string() + ")");
      continue;
    }
    std::error_code removed;
    fs::remove_all(path, removed);
    if (!removed)
      done.push_back(path.string());
  }
  return done;
}
}  // namespace scanhead
