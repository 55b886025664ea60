/// \file comparison_report.cpp
/// \brief comparison.html (comparison_report.hpp).
#include "scanhead/report/comparison_report.hpp"

#include "scanhead/report/html_page.hpp"

namespace scanhead
{
std::string comparisonReportHtml(const RunComparison& c, const std::string& run_a, const std::string& run_b,
                                 const std::string& chart_png)
{
  std::vector<std::vector<std::string>> rows;
  for (const ComparisonRow& row : c.rows)
    rows.push_back(comparisonCells(row));
  std::string body = "<h1>scanhead comparison: " + htmlEscape(c.name_a) + " against " + htmlEscape(c.name_b) +
                     "</h1>\n<p>A: <code>" + htmlEscape(run_a) + "</code>, B: <code>" + htmlEscape(run_b) +
                     "</code> (each folder's report.html has the whole run). B − A: points for shares, else relative."
                     "</p>\n";
  body += htmlTable({"figure", "unit", "A: " + c.name_a, "B: " + c.name_b, "B − A", "better"}, rows, 2, 5);
  if (!chart_png.empty())
    body += htmlPngFigure(chart_png, "The figures of both runs");
  return htmlPage("scanhead comparison: " + c.name_a + " / " + c.name_b, body);
}
}  // namespace scanhead
