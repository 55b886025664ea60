/// \file ros_launch_end.cpp
/// \brief The roslaunch process above this node (ros_launch_end.hpp).
#include "ros_launch_end.hpp"

#include <unistd.h>

#include <fstream>
#include <iterator>
#include <string>

namespace scanhead
{
namespace
{
/// \brief The parent of \p pid from /proc/<pid>/stat ("pid (comm) state ppid …"; comm may hold ')'), or -1.
pid_t parentOf(pid_t pid)
{
  std::ifstream in("/proc/" + std::to_string(pid) + "/stat");
  std::string stat;
  std::getline(in, stat);
  const std::size_t close = stat.rfind(')');
  if (close == std::string::npos || close + 4 >= stat.size())
    return -1;
  return static_cast<pid_t>(std::atol(stat.c_str() + close + 4));  // ") S <ppid>"
}

/// \brief Whether the command line of \p pid runs roslaunch (its script, whatever the interpreter).
bool runsRoslaunch(pid_t pid)
{
  std::ifstream in("/proc/" + std::to_string(pid) + "/cmdline", std::ios::binary);
  std::string cmdline((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  for (std::size_t start = 0; start < cmdline.size();)
  {
    std::size_t end = cmdline.find('\0', start);
    if (end == std::string::npos)
      end = cmdline.size();
    const std::string word = cmdline.substr(start, end - start);
    const std::size_t slash = word.rfind('/');
    if (word.substr(slash == std::string::npos ? 0 : slash + 1) == "roslaunch")
      return true;
    start = end + 1;
  }
  return false;
}
}  // namespace

pid_t roslaunchAncestor()
{
  pid_t pid = ::getppid();
  for (int depth = 0; depth < 4 && pid > 1; ++depth, pid = parentOf(pid))
    if (runsRoslaunch(pid))
      return pid;
  return -1;
}
}  // namespace scanhead
