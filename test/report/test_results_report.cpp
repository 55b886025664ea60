/// \file test_results_report.cpp
/// \brief Issue 17, item 2: the static report page. base64 against RFC 4648's own test vectors, escaping, and the
/// page of a results folder: the figures in their display units, the corners with the highest peaks first, every
/// picture embedded (the 16-bit data PNGs left out) and what the browser test reads (html_page's load check).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "scanhead/report/comparison_report.hpp"
#include "scanhead/report/html_page.hpp"
#include "scanhead/report/png_writer.hpp"
#include "scanhead/report/results_report.hpp"

using scanhead::base64Encode;
using scanhead::htmlEscape;

namespace
{
namespace fs = std::filesystem;

std::size_t occurrences(const std::string& text, const std::string& what)
{
  std::size_t n = 0;
  for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + what.size()))
    ++n;
  return n;
}
}  // namespace

// RFC 4648 §10.
TEST(HtmlPage, Base64TestVectors)
{
  EXPECT_EQ(base64Encode(""), "");
  EXPECT_EQ(base64Encode("f"), "Zg==");
  EXPECT_EQ(base64Encode("fo"), "Zm8=");
  EXPECT_EQ(base64Encode("foo"), "Zm9v");
  EXPECT_EQ(base64Encode("foob"), "Zm9vYg==");
  EXPECT_EQ(base64Encode("fooba"), "Zm9vYmE=");
  EXPECT_EQ(base64Encode("foobar"), "Zm9vYmFy");
  EXPECT_EQ(base64Encode(std::string("\xff\xfe\x00", 3)), "//4A");
}

TEST(HtmlPage, EscapesMarkup)
{
  EXPECT_EQ(htmlEscape("a<b & \"c\" 'd'>"), "a&lt;b &amp; &quot;c&quot; &#39;d&#39;&gt;");
  const std::string table = scanhead::htmlTable({"k", "v"}, {{"<x>", "1.5"}});
  EXPECT_NE(table.find("<td>&lt;x&gt;</td><td class=\"n\">1.5</td>"), std::string::npos) << table;
}

// A results folder with two pictures, a 16-bit data PNG and the YAML files; metrics with three corners.
TEST(ResultsReport, FiguresCornersAndImages)
{
  const fs::path dir = fs::path(::testing::TempDir()) / "results_report";
  fs::remove_all(dir);
  fs::create_directories(dir / "crops");
  scanhead::RgbImage picture(4, 3);
  scanhead::writePng((dir / "energy_map.png").string(), picture);
  scanhead::writePng((dir / "crops" / "part_000.png").string(), picture);
  scanhead::writePng((dir / "energy_map_16bit.png").string(), scanhead::Gray16Image(4, 3));
  std::ofstream(dir / "metrics.yaml") << "job: \"t\"\nsamples: 10\ncorners:\n  - polyline: 0\n";
  std::ofstream(dir / "config.yaml") << "nc:\n  period_s: 1e-05\n";

  scanhead::RunMetrics m;
  m.job_name = "t";
  m.peak_energy_density_jpm2 = 12.96e6;  // 12.96 J/mm²
  m.quality.fill_rate = 0.9861;
  m.track_mean_jpm2 = 4.6e6;
  for (const double peak : {5e6, 11e6, 8e6})
  {
    scanhead::CornerReport c;
    c.corner.polyline = m.corners.size();
    c.energy_peak_jpm2 = peak;
    m.corners.push_back(c);
  }
  scanhead::Job job;
  job.source = "built-in <test>";
  const std::string html = scanhead::resultsReportHtml(dir.string(), m, job);

  EXPECT_NE(html.find("<td class=\"n\">12.96</td><td>J/mm²</td>"), std::string::npos);
  EXPECT_NE(html.find("98.61 %"), std::string::npos);
  EXPECT_NE(html.find("built-in &lt;test&gt;"), std::string::npos);  // escaped
  EXPECT_NE(html.find("the 3 highest energy peaks of 3"), std::string::npos);
  // Highest first: 11 (polyline 1), 8 (2), 5 (0) J/mm²; peak / track mean 11 / 4.6 = 2.39.
  const std::size_t first = html.find("<td>1/0</td>"), second = html.find("<td>2/0</td>"),
                    third = html.find("<td>0/0</td>");
  ASSERT_NE(first, std::string::npos);
  EXPECT_LT(first, second);
  EXPECT_LT(second, third);
  EXPECT_NE(html.find("<td class=\"n\">2.39</td>"), std::string::npos);
  // Two pictures embedded (the 16-bit PNG is data), each as the base64 of its file.
  EXPECT_EQ(occurrences(html, "<img "), 2u);
  std::ifstream png(dir / "energy_map.png", std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(png)), std::istreambuf_iterator<char>());
  EXPECT_NE(html.find("data:image/png;base64," + base64Encode(bytes) + "\""), std::string::npos);
  EXPECT_NE(html.find("Crop part_000.png"), std::string::npos);
  // A 4 px picture is shown 100× (whole factor, at least 400 px), its pixels square.
  EXPECT_NE(html.find("style=\"width: 400px; image-rendering: pixelated\""), std::string::npos);
  // metrics.yaml without its corner list, config.yaml, and the load check.
  EXPECT_NE(html.find("samples: 10\n</pre>"), std::string::npos);
  EXPECT_EQ(html.find("- polyline: 0"), std::string::npos);
  EXPECT_NE(html.find("period_s: 1e-05"), std::string::npos);
  EXPECT_NE(html.find("data-images-loaded"), std::string::npos);
}

// comparison.html: every row of the comparison with its cells (the Markdown's), which run is better, the names
// escaped; no chart, no image.
TEST(ComparisonReport, RowsAndNames)
{
  scanhead::RunComparison c;
  c.name_a = "pd";
  c.name_b = "h<inf>";
  scanhead::ComparisonRow row;
  row.label = "fill rate (hatch)";
  row.unit = "%";
  row.a = 96.46;
  row.b = 93.31;
  row.better = scanhead::Better::Higher;
  c.rows.push_back(row);
  const std::string html = scanhead::comparisonReportHtml(c, "/r/a", "/r/b", "");
  EXPECT_NE(html.find("B: h&lt;inf&gt;"), std::string::npos);
  std::string cells;
  for (const std::string& text : scanhead::comparisonCells(row))
    cells += text + "|";
  EXPECT_EQ(cells, "fill rate (hatch)|%|96.46|93.31|-3.15 pt|A|");
  EXPECT_NE(html.find("<td class=\"n\">-3.15 pt</td><td>A</td>"), std::string::npos) << html;
  EXPECT_EQ(html.find("<img"), std::string::npos);
}
