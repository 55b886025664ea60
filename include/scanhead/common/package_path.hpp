/// \file package_path.hpp
/// \brief Where the package's own files (config/, urdf/, scripts/) are found at run time.
#pragma once

#include <string>

namespace scanhead
{
/// \brief Resolves a config path (optics.urdf_path…): as given when absolute or readable from the
/// working directory, else under the installed share dir, then the source tree; else unchanged.
std::string resolvePackagePath(const std::string& path);
}  // namespace scanhead
