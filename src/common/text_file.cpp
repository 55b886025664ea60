/// \file text_file.cpp
#include "scanhead/common/text_file.hpp"

#include <errno.h>
#include <fcntl.h>
#include <unistd.h>

#include <cstring>
#include <fstream>
#include <iterator>

#include "scanhead/common/errors.hpp"

namespace scanhead
{
std::string readFileOrEmpty(const std::string& path)
{
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

void replaceAll(std::string& text, const std::string& from, const std::string& to)
{
  for (std::size_t at = text.find(from); at != std::string::npos; at = text.find(from, at + to.size()))
    text.replace(at, from.size(), to);
}

void writeTextFile(const std::string& path, const std::string& text)
{
  writeFileBytes(path, text.data(), text.size());
}

void writeFileBytes(const std::string& path, const void* data, std::size_t size)
{
  // POSIX calls, not a std::ofstream: the stream buffers a short text until its destructor, which
  // drops a write error (a full disk left an empty file behind a "success"); here every error is
  // seen, with its errno.
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
  if (fd < 0)
    throw InputError(path + ": cannot write (" + std::strerror(errno) + ")");
  const char* bytes = static_cast<const char*>(data);
  for (std::size_t at = 0; at < size;)
  {
    const ssize_t n = ::write(fd, bytes + at, size - at);
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
