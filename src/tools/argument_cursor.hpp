/// \file argument_cursor.hpp
/// \brief Walks a tool's command line: options, their values, --help, errors with the usage.
#pragma once

#include <cstdlib>
#include <iostream>
#include <string>
#include <vector>

#include "scanhead/chain/batch_chain.hpp"
#include "scanhead/chain/config_io.hpp"
#include "scanhead/common/errors.hpp"
#include "scanhead/common/number_text.hpp"

namespace scanhead
{
/// \code
/// ArgumentCursor args(argc, argv, usage);
/// while (args.next())
///   if (args.is("--out")) out = args.value(); else args.reject();
/// \endcode
class ArgumentCursor
{
public:
  ArgumentCursor(int argc, char** argv, std::string usage) : argc_(argc), argv_(argv), usage_(std::move(usage)) {}

  /// \brief Moves to the next argument; on --help or -h prints the usage and exits 0.
  bool next()
  {
    if (++index_ >= argc_)
      return false;
    arg_ = argv_[index_];
    if (arg_ == "--help" || arg_ == "-h")
    {
      std::cout << usage_;
      std::exit(0);
    }
    return true;
  }
  const std::string& arg() const { return arg_; }
  bool is(const char* option) const { return arg_ == option; }
  bool isOption() const { return arg_.rfind("--", 0) == 0; }

  /// \brief The value that follows the current option. \throws ConfigError if there is none
  std::string value()
  {
    if (index_ + 1 >= argc_ || std::string(argv_[index_ + 1]).rfind("--", 0) == 0)
      throw ConfigError(arg_ + " needs a value\n" + usage_);
    return argv_[++index_];
  }

  /// \throws ConfigError naming the current argument, with the usage
  [[noreturn]] void reject() const { throw ConfigError("unknown argument '" + arg_ + "'\n" + usage_); }

private:
  int argc_;
  char** argv_;
  std::string usage_;
  int index_ = 0;
  std::string arg_;
};

/// \brief An option's value as an integer >= 2 (grid sizes, node counts). \throws ConfigError naming the option
inline int integerAtLeastTwo(const std::string& option, const std::string& text)
{
  double value = 0.0;
  if (parseNumber(text, value) != NumberText::Ok || value != static_cast<int>(value) || value < 2)
    throw ConfigError(option + " must be an integer >= 2 (got '" + text + "')");
  return static_cast<int>(value);
}

/// \brief The --config FILE and --set section.key=value options every tool takes.
struct ConfigArguments
{
  std::string path = "config/scanhead.yaml";  ///< resolved against the package (resolvePackagePath)
  std::vector<std::string> overrides;

  /// \brief Takes the current option if it is --config or --set; false otherwise.
  bool take(ArgumentCursor& args)
  {
    if (args.is("--config"))
      path = args.value();
    else if (args.is("--set"))
      overrides.push_back(args.value());
    else
      return false;
    return true;
  }

  /// \throws ConfigError, InputError as loadChainConfig
  ChainConfig load() const { return loadChainConfig(resolvePackagePath(path), overrides); }
};
}  // namespace scanhead
