/// \file text_file.cpp
#include "scanhead/common/text_file.hpp"

#include <errno.h>
#include <fcntl.h>
#include <unistd.h>

#include <cstring>

#include "scanhead/common/errors.hpp"

namespace scanhead
{
void writeTextFile(const std::string& path, const std::string& text)
{
  // POSIX calls, not a std::ofstream: the stream buffers a short text until its destructor, which
  // drops a write error (a full disk left an empty file behind a "success"); here every error is
  // seen, with its errno.
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
  if (fd < 0)
    throw InputError(path + ": cannot write (" + std::strerror(errno) + ")");
  for (std::size_t at = 0; at < text.size();)
  {
    const ssize_t n = ::write(fd, text.data() + at, text.size() - at);
    if (n < 0 && errno == EINTR)
      continue;
    if (n <= 0)
    {
      const std::string why = n < 0 ? std::strerror(errno) : "nothing written";
      ::close(fd);
      throw InputError(path + ": cannot write (" + why + ")");
    }
    at += static_cast<std::size_t>(n);
  }
  if (::close(fd) != 0)
    throw InputError(path + ": cannot write (" + std::strerror(errno) + ")");
}
}  // namespace scanhead
