#include "scanhead/core/config_check.hpp"

#include <cmath>
#include <sstream>

#include "scanhead/core/errors.hpp"

namespace scanhead
{
void requireSetting(bool ok, const std::string& field, const char* relation, double value)
{
  if (ok && !std::isinf(value))
    return;
  std::ostringstream msg;
  msg << field << " must be " << (std::isinf(value) ? "finite" : relation) << " (got " << value << ")";
  throw ConfigError(msg.str());
}
}  // namespace scanhead
