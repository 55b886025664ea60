/// \file folder_lock.cpp
#include "scanhead/common/folder_lock.hpp"

#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <ctime>
#include <map>
#include <sstream>
#include <system_error>
#include <thread>

namespace scanhead
{
namespace fs = std::filesystem;

namespace
{
fs::path normalised(const std::string& text)
{
  fs::path path = fs::absolute(text).lexically_normal();
  if (path.filename().empty() && path != path.root_path())
    path = path.parent_path();  // "out/" is "out"
  // Symbolic links resolved: the folder locked, staged beside and replaced is the real one, so two
  // runs naming it through different links exclude each other and the link keeps pointing at it.
  std::error_code ec;
  const fs::path real = fs::weakly_canonical(path, ec);
  return ec ? path : real;
}

/// `<parent>/.<name>.lock` of a folder already normalised.
fs::path lockFileBeside(const fs::path& normalised_folder)
{
  return normalised_folder.parent_path() / ("." + normalised_folder.filename().string() + ".lock");
}

std::string hostName()
{
  char name[256] = {};
  if (gethostname(name, sizeof(name) - 1) != 0)
    return "?";
  return name;
}

/// The lock file's "key: value" lines.
std::map<std::string, std::string> parseHolder(const std::string& text)
{
  std::map<std::string, std::string> fields;
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);)
  {
    const std::size_t colon = line.find(": ");
    if (colon != std::string::npos)
      fields[line.substr(0, colon)] = line.substr(colon + 2);
  }
  return fields;
}

/// "scanhead_run, pid 1234 on host h since 2026-12-02 04:10:00 UTC", or "" for no description.
std::string describeHolder(const std::string& text)
{
  const auto fields = parseHolder(text);
  const auto get = [&](const char* key) {
    const auto at = fields.find(key);
    return at == fields.end() ? std::string("?") : at->second;
  };
  if (fields.count("pid") == 0)
    return "";
  std::string description =
      get("program") + ", pid " + get("pid") + " on host " + get("host") + " since " + get("since");
  // The holder's pid is gone but the lock is held: a child that inherited the descriptor holds it.
  if (get("host") == hostName())
  {
    char* end = nullptr;
    const long pid = std::strtol(get("pid").c_str(), &end, 10);
    if (end != nullptr && *end == '\0' && pid > 0 && kill(static_cast<pid_t>(pid), 0) != 0 && errno == ESRCH)
      description += " (that process has ended; a process it started still holds the lock)";
  }
  return description;
}

std::string readAll(int fd)
{
  std::string text;
  char buffer[1024];
  for (off_t at = 0;;)
  {
    const ssize_t n = pread(fd, buffer, sizeof(buffer), at);
    if (n < 0 && errno == EINTR)
      continue;
    if (n <= 0 || text.size() > 65536)
      return text;
    text.append(buffer, static_cast<std::size_t>(n));
    at += n;
  }
}
}  // namespace

fs::path FolderLock::lockFileOf(const fs::path& folder)
{
  return lockFileBeside(normalised(folder.string()));
}

std::string FolderLock::holderOf(const fs::path& folder)
{
  const int fd = ::open(lockFileOf(folder).c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0)
    return "";
  const std::string text = readAll(fd);
  ::close(fd);
  return describeHolder(text);
}

FolderLock::FolderLock(const std::string& folder_text)
  : folder_(normalised(folder_text))
{
  if (folder_ == folder_.root_path() || folder_.filename() == "." || folder_.filename() == "..")
    throw InputError(folder_text + ": not a folder that can be written (name a folder below it)");
  const fs::path parent = folder_.parent_path();
  fs::path missing;  // the outermost parent that does not exist yet
  for (fs::path p = parent; !p.empty() && !fs::exists(p) && p != p.root_path(); p = p.parent_path())
    missing = p;
  std::error_code ec;
  fs::create_directories(parent, ec);
  if (ec)
    throw InputError(parent.string() + ": cannot create (" + ec.message() + ")");
  created_ = missing;
  lock_file_ = lockFileBeside(folder_);
  const fs::path& file = lock_file_;
  for (int attempt = 0;; ++attempt)
  {
    const int fd = ::open(file.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (fd < 0)
    {
      const std::string why = std::strerror(errno);
      release();
      throw InputError(file.string() + ": cannot create the lock file of " + folder_.string() + " (" + why + ")");
    }
    if (::flock(fd, LOCK_EX | LOCK_NB) != 0)
    {
      const int error = errno;
      if (error == EINTR)
      {
        ::close(fd);
        continue;
      }
      if (error != EWOULDBLOCK)
      {
        ::close(fd);
        release();
        throw InputError(file.string() + ": cannot lock (" + std::strerror(error) + ")");
      }
      // The holder writes its description right after taking the lock: give it a moment.
      std::string holder;
      for (int wait = 0; wait < 50 && (holder = describeHolder(readAll(fd))).empty(); ++wait)
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
      ::close(fd);
      if (holder.empty())
        holder = "another process (its lock file names no holder)";
      throw FolderBusyError(folder_.string() + ": being written by " + holder + " (lock file " + file.string() +
                            "); wait for that run to end, stop it, or choose another output folder");
    }
    // Ours only if the path still names the file we locked: a holder that released meanwhile
    // removed it, and the next taker creates a new one.
    struct stat held = {}, named = {};
    if (::fstat(fd, &held) == 0 && ::stat(file.c_str(), &named) == 0 && held.st_dev == named.st_dev &&
        held.st_ino == named.st_ino)
    {
      fd_ = fd;
      break;
    }
    ::close(fd);
    if (attempt >= 1000)
    {
      release();
      throw InputError(file.string() + ": the lock file keeps being replaced; cannot lock " + folder_.string());
    }
  }
  // Who holds it, for the message of the next taker (best effort: a full disk costs the names only).
  char since[64] = "?";
  const std::time_t now = std::time(nullptr);
  std::tm utc = {};
  if (gmtime_r(&now, &utc) != nullptr)
    std::strftime(since, sizeof(since), "%Y-%m-%d %H:%M:%S UTC", &utc);
  const std::string text = "pid: " + std::to_string(getpid()) + "\nhost: " + hostName() +
                           "\nprogram: " + program_invocation_short_name + "\nsince: " + since + "\n";
  if (::ftruncate(fd_, 0) == 0 && ::pwrite(fd_, text.data(), text.size(), 0) < 0)
  {
    // ignored: the lock holds without its description
  }
}

FolderLock::~FolderLock()
{
  release();
}

FolderLock::FolderLock(FolderLock&& other) noexcept
  : folder_(std::move(other.folder_))
  , lock_file_(std::move(other.lock_file_))
  , created_(std::move(other.created_))
  , fd_(other.fd_)
{
  other.fd_ = -1;
  other.created_.clear();
}

FolderLock& FolderLock::operator=(FolderLock&& other) noexcept
{
  if (this != &other)
  {
    release();
    folder_ = std::move(other.folder_);
    lock_file_ = std::move(other.lock_file_);
    created_ = std::move(other.created_);
    fd_ = other.fd_;
    other.fd_ = -1;
    other.created_.clear();
  }
  return *this;
}

void FolderLock::release() noexcept
{
  std::error_code ec;
  if (fd_ >= 0)
  {
    ::unlink(lock_file_.c_str());  // while still held: see the file comment
    ::close(fd_);
    fd_ = -1;
  }
  // Parents created for a folder that was never written go again (only if empty).
  if (!created_.empty() && !fs::exists(folder_, ec))
    for (fs::path p = folder_.parent_path(); !p.empty(); p = p.parent_path())
    {
      if (!fs::remove(p, ec) || p == created_)
        break;
    }
  created_.clear();
}
}  // namespace scanhead
