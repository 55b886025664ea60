/// \file command_line.hpp
/// \brief The tools' command lines on CLI11: the options every tool shares (--config, --set), value
/// checks whose messages name the option and the value, and one parse call that turns every
/// command-line error into a one-line scanhead::ConfigError.
///
/// Header-only on purpose: the tools include it, the nodes (which link scanhead_tools_support) do
/// not, so only the tool executables need CLI11.
/// \code
/// CLI::App app("what the tool does", "scanhead_tool");
/// scanhead::configureApp(app);
/// app.add_option("--out", out, "results folder")->type_name("DIR");
/// scanhead::ConfigArguments config;
/// config.addTo(app, "nc.fir_t1_s=300e-6");
/// if (!scanhead::parseCommandLine(app, argc, argv))
///   return 0;  // --help was printed
/// \endcode
#pragma once

#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <iostream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "scanhead/chain/batch_chain.hpp"
#include "scanhead/chain/config_io.hpp"
#include "scanhead/common/errors.hpp"
#include "scanhead/common/number_text.hpp"

namespace scanhead
{
/// \brief The settings every tool's App shares; call before adding options and subcommands.
/// An option given twice keeps its last value (as the tools always did); subcommands see the
/// main command's options (--config, --set, ...) after the command word.
inline void configureApp(CLI::App& app)
{
  app.option_defaults()->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);
  app.allow_extras();  // unknown arguments are reported by parseCommandLine, naming the argument
  app.fallthrough();
  app.get_formatter()->column_width(28);
}

/// \brief The --config FILE and --set section.key=value options every tool takes.
struct ConfigArguments
{
  std::string path = "config/scanhead.yaml";  ///< resolved against the package (resolvePackagePath)
  std::vector<std::string> overrides;

  /// \brief Adds --config and the repeatable --set to \p app; \p set_example is shown in the help.
  void addTo(CLI::App& app, const std::string& set_example)
  {
    app.add_option("--config", path, "configuration YAML (default: the package's config/scanhead.yaml)")
        ->type_name("FILE");
    app.add_option("--set", overrides, "override one setting, e.g. --set " + set_example + " (repeatable)")
        ->type_name("KEY=VALUE")
        ->allow_extra_args(false);  // one value per --set: the next word is the tool's again
  }

  /// \throws ConfigError, InputError as loadChainConfig
  ChainConfig load() const { return loadChainConfig(resolvePackagePath(path), overrides); }
};

/// \brief Value checks for CLI11 options, attached with Option::transform (not check(), which
/// would run them on a copy of the text). A failed check reads "OPTION: must be ... (got 'TEXT')".
/// The number checks read the text as the core does (parseNumber: std::stod, finite) and hand CLI11
/// that double's 17-digit text, so the option holds the same double bit for bit (CLI11 itself
/// would read through long double and round twice); integers are handed over as integer text.
namespace check
{
/// \brief An integer >= \p minimum (grid sizes, node counts, repeats); "1e2" and "65.0" are integers.
inline CLI::Validator integerAtLeast(int minimum)
{
  return CLI::Validator(
      [minimum](std::string& text) -> std::string {
        double value = 0.0;
        if (parseNumber(text, value) != NumberText::Ok || value < minimum || value > 2147483647.0 ||
            value != std::floor(value))
          return "must be an integer >= " + std::to_string(minimum) + " (got '" + text + "')";
        text = std::to_string(static_cast<int>(value));
        return {};
      },
      "INT>=" + std::to_string(minimum));
}

/// \brief Most probes per axis of a correction-table check (scanhead_table --probes, scanhead_optics residual
/// --probes): P² probes, each a table lookup and a forward model (~1 µs): 2049² ≈ 4.2 M probes, a few seconds.
constexpr int kMaxProbesPerAxis = 2049;

/// \brief An integer in [\p minimum, \p maximum] (grid and probe counts whose work grows as their square).
inline CLI::Validator integerIn(int minimum, int maximum)
{
  return CLI::Validator(
      [minimum, maximum](std::string& text) -> std::string {
        double value = 0.0;
        if (parseNumber(text, value) != NumberText::Ok || value < minimum || value > maximum ||
            value != std::floor(value))
          return "must be an integer in [" + std::to_string(minimum) + ", " + std::to_string(maximum) + "] (got '" +
                 text + "')";
        text = std::to_string(static_cast<int>(value));
        return {};
      },
      "INT in [" + std::to_string(minimum) + ", " + std::to_string(maximum) + "]");
}

/// \brief A finite number > 0.
inline CLI::Validator positiveNumber()
{
  return CLI::Validator(
      [](std::string& text) -> std::string {
        double value = 0.0;
        if (parseNumber(text, value) != NumberText::Ok || !(value > 0.0))
          return "must be a positive number (got '" + text + "')";
        text = fullPrecisionText(value);  // CLI11 reads via long double: 17 digits read back exactly
        return {};
      },
      "NUMBER>0");
}

/// \brief A finite number >= 0.
inline CLI::Validator nonNegativeNumber()
{
  return CLI::Validator(
      [](std::string& text) -> std::string {
        double value = 0.0;
        if (parseNumber(text, value) != NumberText::Ok || !(value >= 0.0))
          return "must be a number >= 0 (got '" + text + "')";
        text = fullPrecisionText(value);  // CLI11 reads via long double: 17 digits read back exactly
        return {};
      },
      "NUMBER>=0");
}

/// \brief A finite number (no nan, no inf).
inline CLI::Validator finiteNumber()
{
  return CLI::Validator(
      [](std::string& text) -> std::string {
        double value = 0.0;
        if (parseNumber(text, value) != NumberText::Ok)
          return "must be a finite number (got '" + text + "')";
        text = fullPrecisionText(value);  // CLI11 reads via long double: 17 digits read back exactly
        return {};
      },
      "");  // the option's type name says it
}

/// \brief A decimal integer in [0, 2^64) (seeds).
inline CLI::Validator unsigned64()
{
  return CLI::Validator(
      [](std::string& text) -> std::string {
        errno = 0;
        char* end = nullptr;
        std::strtoull(text.c_str(), &end, 10);
        if (text.empty() || text.find_first_not_of("0123456789") != std::string::npos || *end != '\0' ||
            errno == ERANGE)
          return "must be an integer in [0, 2^64) (got '" + text + "')";
        return {};
      },
      "UINT64");
}

/// \brief One of \p words, e.g. {"x", "y"}: "must be x or y (got 'z')".
inline CLI::Validator oneOf(const std::vector<std::string>& words)
{
  std::string list;
  for (std::size_t k = 0; k < words.size(); ++k)
    list += (k == 0 ? "" : k + 1 == words.size() ? " or " : ", ") + words[k];
  return CLI::Validator(
      [words, list](std::string& text) -> std::string {
        for (const std::string& w : words)
          if (text == w)
            return {};
        return "must be " + list + " (got '" + text + "')";
      },
      "");  // the option's type name lists the words
}
}  // namespace check

namespace detail
{
inline bool looksLikeOption(const std::string& word)
{
  return word.size() > 1 && word[0] == '-' && !(word[1] >= '0' && word[1] <= '9') && word[1] != '.';
}

/// "RUN_A RUN_B", or "no arguments": the positional arguments \p app takes.
inline std::string positionalNames(const CLI::App& app)
{
  std::string names;
  for (const CLI::Option* o : app.get_options([](const CLI::Option* o) { return o->get_positional(); }))
    names += (names.empty() ? "" : " ") + o->get_name();
  return names.empty() ? "no arguments" : names;
}

/// The command word of a tool with subcommands: "no command" / "unknown command 'X'", listing them.
inline void checkCommand(const CLI::App& app)
{
  const std::vector<const CLI::App*> commands = app.get_subcommands([](const CLI::App*) { return true; });
  if (commands.empty() || !app.get_subcommands().empty())
    return;
  std::string list;
  for (const CLI::App* c : commands)
    list += (list.empty() ? "" : ", ") + c->get_name();
  for (const std::string& word : app.remaining(true))
    if (!looksLikeOption(word))
      throw ConfigError("unknown command '" + word + "' (commands: " + list + ")");
  throw ConfigError("no command (commands: " + list + ")");
}

/// Arguments no option or positional took: the first one, named; an option of another command says so.
inline void checkExtras(const CLI::App& app)
{
  const std::vector<std::string> extras = app.remaining(true);
  if (extras.empty())
    return;
  const std::string& word = extras.front();
  const std::vector<CLI::App*> selected = app.get_subcommands();
  const CLI::App* command = selected.empty() ? &app : selected.front();
  if (!looksLikeOption(word))
    throw ConfigError("unexpected argument '" + word + "' (" + command->get_name() + " takes " +
                      positionalNames(*command) + ")");
  const std::string name = word.substr(0, word.find('='));
  if (command != &app)
    for (const CLI::App* other : app.get_subcommands([](const CLI::App*) { return true; }))
      if (other != command && other->get_option_no_throw(name) != nullptr)
        throw ConfigError(name + " is not an option of " + command->get_name());
  throw ConfigError("unknown argument '" + word + "'");
}

/// An option whose value is another option ("--out --quiet"): the value is missing.
inline void checkValues(const CLI::App& app)
{
  for (const CLI::Option* o : app.get_options())
  {
    if (o->get_positional() || o->get_items_expected_max() == 0)
      continue;
    for (const std::string& value : o->results())
      if (value.rfind("--", 0) == 0)
        throw ConfigError(o->get_name() + " needs a value (got the option '" + value + "')");
  }
  for (const CLI::App* sub : app.get_subcommands())
    checkValues(*sub);
}
}  // namespace detail

/// \brief Parses the command line into the options' variables.
/// \return false if --help (or -h) was given: the help was printed to stdout, exit 0
/// \throws ConfigError with a one-line message naming the argument or option that is wrong
inline bool parseCommandLine(CLI::App& app, int argc, char** argv)
{
  try
  {
    app.parse(argc, argv);
  }
  catch (const CLI::CallForHelp& e)
  {
    app.exit(e, std::cout, std::cerr);
    return false;
  }
  catch (const CLI::ParseError& e)
  {
    detail::checkCommand(app);  // a missing or misspelt command word explains the rest
    const std::vector<CLI::App*> selected = app.get_subcommands();
    const CLI::App* command = selected.empty() ? &app : selected.front();
    const std::string message = e.what();
    if (dynamic_cast<const CLI::RequiredError*>(&e) != nullptr)
    {
      const std::string names = detail::positionalNames(*command);
      const std::string missing = message.substr(0, message.find(' '));
      if ((" " + names + " ").find(" " + missing + " ") != std::string::npos)
        throw ConfigError(message + " (" + command->get_name() + " takes " + names + ")");
      if (command != &app && command->get_option_no_throw(missing) != nullptr)
        throw ConfigError(message + " by " + command->get_name());
    }
    throw ConfigError(message);
  }
  detail::checkCommand(app);
  detail::checkExtras(app);
  detail::checkValues(app);
  return true;
}
}  // namespace scanhead
