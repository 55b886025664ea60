/// \file number_text.hpp
/// \brief Strict text → number: the whole text must be one finite number (job files, config, specs).
#pragma once

#include <string>

namespace scanhead
{
enum class NumberText
{
  Ok,         ///< the whole text is a finite number
  NotNumber,  ///< empty, trailing characters, or no number at all
  NotFinite   ///< nan, inf
};

/// \brief Parses \p text into \p value (unchanged unless Ok).
NumberText parseNumber(const std::string& text, double& value);

/// \brief \p value with 17 significant digits ("%.17g"): reads back bit-exactly, so files and
/// messages written with it reproduce the number that was used.
std::string fullPrecisionText(double value);
/// \brief The shortest "%.<n>g" text (n = 1 … 17) that reads back as exactly \p value: 0.1 as "0.1",
/// not "0.10000000000000001" (defect set files, names of random sets).
std::string shortestText(double value);
/// \brief \p value with 6 significant digits ("%.6g"): for reports read by people.
std::string sixDigitText(double value);
/// \brief \p value for YAML: full precision (fullPrecisionText), NaN as .nan, ±infinity as .inf / -.inf.
std::string yamlNumber(double value);
/// \brief \p text as a YAML double-quoted scalar (quotes and backslashes escaped).
std::string yamlQuoted(const std::string& text);
}  // namespace scanhead
