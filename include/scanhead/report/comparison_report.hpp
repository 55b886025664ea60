/// \file comparison_report.hpp
/// \brief comparison.html of scanhead_compare --out: the two runs' figures side by side (the table of
/// run_comparison.hpp, with which run is better) and the comparison chart embedded, one self-contained page.
#pragma once

#include <string>

#include "scanhead/metrics/run_comparison.hpp"

namespace scanhead
{
/// \brief The page of \p comparison between the results folders \p run_a and \p run_b (named on the page);
/// \p chart_png: comparison.png's bytes, or empty (no chart).
std::string comparisonReportHtml(const RunComparison& comparison, const std::string& run_a, const std::string& run_b,
                                 const std::string& chart_png);
}  // namespace scanhead
