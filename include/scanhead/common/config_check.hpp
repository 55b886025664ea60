/// \file config_check.hpp
/// \brief The one check every config validate() uses, so all messages read alike.
#pragma once

#include <initializer_list>
#include <string>

namespace scanhead
{
/// \brief Throws ConfigError "<field> must be <relation> (got <value>)" unless \p ok, and
/// "<field> must be finite (got inf)" for an infinite value. Write \p ok as a comparison that NaN
/// fails (e.g. `x > 0`), so NaN is rejected with the relation it broke.
void requireSetting(bool ok, const std::string& field, const std::string& relation, double value);

/// \brief Throws ConfigError "<field> must be <relation> (got <value>)" (for checks requireSetting
/// cannot express, e.g. integer settings or relations between fields).
[[noreturn]] void failSetting(const std::string& field, const std::string& relation, double value);

/// \brief Throws ConfigError "<field>: unknown '<value>' (known: a, b, c)" unless \p value is one
/// of \p choices.
void requireChoice(const std::string& value, const std::string& field, std::initializer_list<const char*> choices);
}  // namespace scanhead
