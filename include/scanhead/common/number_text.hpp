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
/// \brief The shortest "%.<n>g" text (n = \p min_digits … 17) that reads back as exactly \p value:
/// 0.1 as "0.1", not "0.10000000000000001" (defect set files, names of random sets). A larger
/// \p min_digits keeps round numbers out of exponent form: 100 is "1e+02" from n = 1, "100" from
/// n = 3 on (job statistics use 10, messages about scan-path fields 15). NaN and ±infinity give
/// their "%.17g" text.
/// \pre 1 <= \p min_digits <= 17 (clamped)
std::string shortestText(double value, int min_digits = 1);
/// \brief \p value with 6 significant digits ("%.6g"): for reports read by people. The same
/// characters as a default-formatted std::ostream (precision 6).
std::string sixDigitText(double value);
/// \brief \p value with \p digits significant digits ("%.<digits>g", digits >= 1): the same
/// characters as a default-formatted std::ostream with precision(digits). sixDigitText and
/// fullPrecisionText are the cases 6 and 17; 9 (messages, km0 reports), 12 (generated job
/// sources) and 4 (run comparison tables) are the others in use.
std::string significantText(double value, int digits);
/// \brief \p value with \p decimals digits after the point ("%.<decimals>f", decimals >= 0; no
/// exponent form, however large the value): fixed-width table columns.
std::string fixedText(double value, int decimals);
/// \brief \p value as std::to_chars(first, last, value) writes it: the shortest text that reads
/// back as exactly \p value, in plain or exponent form whichever is shorter (100 as "100", 1e-07
/// as "1e-07", 1e+22 as "1e+22"); no "%g" format gives these characters. "nan", "inf", "-inf".
std::string toCharsText(double value);
/// \brief \p value for YAML: full precision (fullPrecisionText), NaN as .nan, ±infinity as .inf / -.inf.
std::string yamlNumber(double value);
/// \brief \p text as a YAML double-quoted scalar (quotes and backslashes escaped).
std::string yamlQuoted(const std::string& text);
}  // namespace scanhead
