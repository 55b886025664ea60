/// \file cli_text.hpp
/// \brief Private: a cursor over CLI text (header and ASCII geometry) that counts lines and skips
/// `//` comments; numbers are read in place with std::from_chars (no allocation, no locale).
#pragma once

#include <charconv>
#include <cstddef>
#include <cstring>
#include <string>
#include <string_view>

#include "scanhead/common/errors.hpp"

namespace scanhead
{
namespace cli
{
[[noreturn]] inline void failAtLine(const std::string& source, std::size_t line, const std::string& what)
{
  throw InputError(source + ":" + std::to_string(line) + ": " + what);
}

inline bool isNameChar(char c)
{
  return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_';
}

struct TextCursor
{
  const char* p = nullptr;
  const char* end = nullptr;
  std::size_t line = 1;

  bool atEnd() const { return p >= end; }
  std::size_t remaining() const { return static_cast<std::size_t>(end - p); }
  bool startsWith(std::string_view s) const
  {
    return remaining() >= s.size() && std::memcmp(p, s.data(), s.size()) == 0;
  }

  /// \brief Skips a comment starting at p ("//"): up to and including the next "//" on the
  /// line, or up to (not including) the end of the line.
  void skipComment()
  {
    p += 2;
    while (p < end && *p != '\n')
    {
      if (*p == '/' && p + 1 < end && p[1] == '/')
      {
        p += 2;
        return;
      }
      ++p;
    }
  }

  /// \brief Skips white space (counting lines) and comments.
  void skipBlank()
  {
    while (p < end)
    {
      const char c = *p;
      if (c == '\n')
      {
        ++line;
        ++p;
      }
      else if (c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v')
        ++p;
      else if (c == '/' && p + 1 < end && p[1] == '/')
        skipComment();
      else
        break;
    }
  }

  /// \brief Skips spaces and tabs on the current line.
  void skipSpaces()
  {
    while (p < end && (*p == ' ' || *p == '\t'))
      ++p;
  }

  /// \brief At "$$NAME": returns NAME and moves past it; otherwise returns an empty view.
  std::string_view command()
  {
    if (!startsWith("$$"))
      return {};
    const char* name = p + 2;
    const char* q = name;
    while (q < end && isNameChar(*q))
      ++q;
    p = q;
    return std::string_view(name, static_cast<std::size_t>(q - name));
  }

  /// \brief The token at p (up to white space, ',' or end), for messages.
  std::string token(std::size_t max_chars = 24) const;
};

/// \brief Parses the number starting at \p p (optional '+', no leading space). On success
/// returns the first byte after it, else nullptr. \p out_of_range is set for overflow.
inline const char* readNumber(const char* p, const char* end, double& value, bool& out_of_range)
{
  out_of_range = false;
  const char* start = p;
  if (p < end && *p == '+' && p + 1 < end && ((p[1] >= '0' && p[1] <= '9') || p[1] == '.'))
    ++start;
  const std::from_chars_result r = std::from_chars(start, end, value, std::chars_format::general);
  if (r.ec == std::errc::result_out_of_range)
  {
    out_of_range = true;
    return nullptr;
  }
  if (r.ec != std::errc())
    return nullptr;
  return r.ptr;
}

/// \brief A number token ends at white space, ',', '/', '$' or the end of the text.
inline bool isNumberEnd(const char* p, const char* end)
{
  if (p >= end)
    return true;
  const char c = *p;
  return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\f' || c == '\v' || c == ',' || c == '/' || c == '$';
}
}  // namespace cli
}  // namespace scanhead
