#include "scanhead/core/number_text.hpp"

#include <cmath>
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
}  // namespace scanhead
