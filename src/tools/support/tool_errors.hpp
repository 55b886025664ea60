/// \file tool_errors.hpp
/// \brief The one text a tool prints for an exception that ends it: the message of the project's
/// own errors (they name the file, line or key), and for an allocation failure what it means and
/// what to do, instead of a bare "std::bad_alloc".
#pragma once

#include <exception>
#include <new>
#include <string>

namespace scanhead
{
/// \brief What a tool says for \p e after "<tool>: error: ".
inline std::string toolErrorText(const std::exception& e)
{
  if (dynamic_cast<const std::bad_alloc*>(&e) != nullptr)
    return "out of memory: a setting or input asks for more memory than this machine has (batch runs are "
           "planned and bounded by limits.*; see --help for this tool's size options)";
  return e.what();
}
}  // namespace scanhead
