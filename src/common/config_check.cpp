#include "scanhead/common/config_check.hpp"

#include <cmath>
#include <sstream>

#include "scanhead/common/errors.hpp"

namespace scanhead
{
void failSetting(const std::string& field, const std::string& relation, double value)
{
  std::ostringstream msg;
  msg << field << " must be " << relation << " (got " << value << ")";
  throw ConfigError(msg.str());
}

void requireSetting(bool ok, const std::string& field, const std::string& relation, double value)
{
  if (std::isinf(value))
    failSetting(field, "finite", value);
  if (!ok)
    failSetting(field, relation, value);
}

void requireChoice(const std::string& value, const std::string& field, std::initializer_list<const char*> choices)
{
  std::string known;
  for (const char* choice : choices)
  {
    if (value == choice)
      return;
    known += (known.empty() ? "" : ", ") + std::string(choice);
  }
  throw ConfigError(field + ": unknown '" + value + "' (known: " + known + ")");
}
}  // namespace scanhead
