/// \file text_file.hpp
/// \brief Writing a whole text file, with the error every writer of the project reports.
#pragma once

#include <string>

namespace scanhead
{
/// \brief Writes \p text to \p path (binary, replacing the file).
/// \throws InputError "<path>: cannot write (<strerror>)" if the file cannot be written
void writeTextFile(const std::string& path, const std::string& text);
}  // namespace scanhead
