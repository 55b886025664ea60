/// \file errors.hpp
/// \brief Typed exceptions of the core: every message names the file, line or field at fault.
#pragma once

#include <stdexcept>
#include <string>

namespace scanhead
{
/// \brief A configuration value is missing, unknown or out of range (names the field and value).
class ConfigError : public std::runtime_error
{
public:
  using std::runtime_error::runtime_error;
};

/// \brief An input file (job, URDF, table) is malformed (names the file, line and field).
class InputError : public std::runtime_error
{
public:
  using std::runtime_error::runtime_error;
};

/// \brief A numerical procedure did not converge or left its domain (e.g. Newton inverse).
class NumericalError : public std::runtime_error
{
public:
  using std::runtime_error::runtime_error;
};
}  // namespace scanhead
