// Peak memory of this process, for the tools' reports (the core never asks the OS).
#pragma once

#include <cstddef>
#include <fstream>
#include <string>

namespace scanhead
{
/// \brief Peak resident set size [bytes] (Linux VmHWM), 0 where /proc is not available.
inline std::size_t processPeakResidentBytes()
{
  std::ifstream status("/proc/self/status");
  std::string key;
  while (status >> key)
  {
    if (key == "VmHWM:")
    {
      std::size_t kib = 0;
      status >> kib;
      return kib * 1024;
    }
    status.ignore(1 << 12, '\n');
  }
  return 0;
}
}  // namespace scanhead
