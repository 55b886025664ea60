#include "scanhead/common/number_text.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>

namespace scanhead
{
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

std::string shortestText(double value)
{
  char buffer[40];
  for (int digits = 1; digits <= 17; ++digits)
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
