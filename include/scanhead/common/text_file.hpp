/// \file text_file.hpp
/// \brief Writing a whole file (text or bytes), with the error every writer of the project reports; reading one back;
/// replacing text in it.
#pragma once

#include <cstddef>
#include <string>

namespace scanhead
{
/// \brief Writes \p text to \p path (binary, replacing the file).
/// \throws InputError "<path>: cannot write (<strerror>)" if the file cannot be written
void writeTextFile(const std::string& path, const std::string& text);

/// \brief The whole content of \p path, or "" if it cannot be opened (a status or log file not written yet).
std::string readFileOrEmpty(const std::string& path);

/// \brief Replaces every occurrence of \p from in \p text by \p to (left to right; a replacement is not searched
/// again).
void replaceAll(std::string& text, const std::string& from, const std::string& to);

/// \brief Writes \p size bytes at \p data to \p path (replacing the file), with POSIX calls so
/// that every error is seen with its own errno (a full disk included).
/// \throws InputError "<path>: cannot write (<strerror>)" if the file cannot be written
void writeFileBytes(const std::string& path, const void* data, std::size_t size);
}  // namespace scanhead
