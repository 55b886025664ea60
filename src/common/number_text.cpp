#include "scanhead/common/number_text.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>

namespace scanhead
{
namespace
{
/// The text \p print (a call of snprintf(buffer, size, …)) writes, of any length ("%.2f" of
/// 1e300 has 303 characters).
template <class Print>
std::string printed(Print print)
{
  char buffer[64];
  const int n = print(buffer, sizeof buffer);
  if (n < 0)
    return std::string();
  if (static_cast<std::size_t>(n) < sizeof buffer)
    return std::string(buffer, static_cast<std::size_t>(n));
  std::string out(static_cast<std::size_t>(n) + 1, '\0');
  print(&out[0], out.size());
  out.resize(static_cast<std::size_t>(n));
  return out;
}
}  // namespace

NumberText parseNumber(const std::string& text, double& value)
{
  std::size_t used = 0;
  double parsed = 0.0;
  try
  {
    parsed = std::stod(text, &used);
  }
  catch (const std::out_of_range&)
  {
    return NumberText::NotFinite;  // overflows to ±inf
  }
  catch (const std::invalid_argument&)
  {
    return NumberText::NotNumber;
  }
  if (used != text.size())
    return NumberText::NotNumber;
  if (!std::isfinite(parsed))
    return NumberText::NotFinite;
  value = parsed;
  return NumberText::Ok;
}

std::string fullPrecisionText(double value)
{
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.17g", value);
  return buffer;
}

std::string shortestText(double value, int min_digits)
{
  char buffer[40];
  for (int digits = std::min(std::max(min_digits, 1), 17); digits <= 17; ++digits)
  {
    std::snprintf(buffer, sizeof buffer, "%.*g", digits, value);
    if (std::strtod(buffer, nullptr) == value)
      break;
  }
  return buffer;
}

std::string sixDigitText(double value)
{
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.6g", value);
  return buffer;
}

std::string significantText(double value, int digits)
{
  return printed([&](char* buffer, std::size_t size) { return std::snprintf(buffer, size, "%.*g", digits, value); });
}

std::string fixedText(double value, int decimals)
{
  return printed([&](char* buffer, std::size_t size) { return std::snprintf(buffer, size, "%.*f", decimals, value); });
}

std::string toCharsText(double value)
{
  char buffer[32];  // the longest shortest form: "-2.2250738585072014e-308", 24 characters
  const std::to_chars_result r = std::to_chars(buffer, buffer + sizeof buffer, value);
  return std::string(buffer, r.ptr);
}

std::string yamlNumber(double value)
{
  if (std::isnan(value))
    return ".nan";
  if (std::isinf(value))
    return value > 0 ? ".inf" : "-.inf";
  return fullPrecisionText(value);
}

std::string yamlQuoted(const std::string& text)
{
  std::string out = "\"";
  for (char c : text)
  {
    if (c == '"' || c == '\\')
      out += '\\';
    out += c;
  }
  return out + "\"";
}
}  // namespace scanhead
