#include "scanhead/common/package_path.hpp"

#include <fstream>

namespace scanhead
{
std::string resolvePackagePath(const std::string& path)
{
  if (path.empty() || path.front() == '/' || std::ifstream(path).good())
    return path;
  for (const std::string& root : {std::string(SCANHEAD_SHARE_DIR), std::string(SCANHEAD_SOURCE_DIR)})
  {
    const std::string candidate = root + "/" + path;
    if (std::ifstream(candidate).good())
      return candidate;
  }
  return path;
}
}  // namespace scanhead
