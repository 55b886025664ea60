/// \file study_summary.cpp
/// \brief summary.csv and summary.md of a study (study_summary.hpp).
#include "scanhead/study/study_summary.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <sstream>

#include "scanhead/common/errors.hpp"
#include "scanhead/common/number_text.hpp"
#include "scanhead/common/text_file.hpp"
#include "scanhead/common/yaml_document.hpp"
#include "scanhead/report/html_page.hpp"

namespace scanhead
{
namespace
{
namespace fs = std::filesystem;

/// \brief The keys of "key=value;key=value" in order.
std::vector<std::pair<std::string, std::string>> gridValues(const std::string& text)
{
  std::vector<std::pair<std::string, std::string>> out;
  std::istringstream parts(text);
  for (std::string part; std::getline(parts, part, ';');)
  {
    const std::size_t eq = part.find('=');
    if (eq != std::string::npos)
      out.emplace_back(part.substr(0, eq), part.substr(eq + 1));
  }
  return out;
}

std::string csvField(const std::string& text)
{
  if (text.find_first_of(",\"\n") == std::string::npos)
    return text;
  std::string out = "\"";
  for (const char c : text)
    out += c == '"' ? std::string("\"\"") : std::string(1, c);
  return out + "\"";
}

const char* stateName(CaseState s)
{
  return s == CaseState::Done ? "done" : s == CaseState::Failed ? "failed" : "pending";
}

double number(const YAML::Node& node, const std::string& path, const std::string& key)
{
  if (!node || !node.IsScalar())
    throw InputError(path + ": " + key + ": missing");
  const std::string& text = node.Scalar();
  if (text == ".nan" || text == ".NaN")
    return std::nan("");  // a figure without points (no contour in the job)
  if (text == ".inf" || text == "-.inf")
    return text[0] == '-' ? -HUGE_VAL : HUGE_VAL;
  double value = 0.0;
  if (parseNumber(text, value) != NumberText::Ok)
    throw InputError(path + ": " + key + ": '" + node.Scalar() + "' is not a number");
  return value;
}

/// \brief A share in %, "" for a figure without points (NaN).
std::string percent(double share)
{
  return std::isnan(share) ? std::string() : fixedText(100.0 * share, 2);
}
}  // namespace

CaseFigures readCaseFigures(const std::string& metrics_path)
{
  std::ifstream in(metrics_path, std::ios::binary);
  if (!in)
    throw InputError(metrics_path + ": cannot open");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  // The per-corner list is most of a layer's file (MBs for a THESIS layer): the figures are all before it.
  const std::size_t corners = text.find("\ncorners:");
  if (corners != std::string::npos)
    text.resize(corners + 1);
  YamlLimits limits = yamlSettingsLimits("a metrics file");
  limits.max_bytes = std::max<std::size_t>(limits.max_bytes, text.size() + 1);
  const YAML::Node m = parseYamlDocument(text, metrics_path, limits);
  CaseFigures f;
  const std::string& p = metrics_path;
  f.layer_time_s = number(m["layer_time_s"], p, "layer_time_s");
  f.fill_rate = number(m["fill_rate"], p, "fill_rate");
  f.peak_energy_jmm2 = number(m["peak_energy_density_jpm2"], p, "peak_energy_density_jpm2") * 1e-6;
  f.commanded_energy_j = number(m["commanded_energy_j"], p, "commanded_energy_j");
  f.laser_early = static_cast<unsigned long long>(number(m["laser_early_samples"], p, "laser_early_samples"));
  f.laser_late = static_cast<unsigned long long>(number(m["laser_late_samples"], p, "laser_late_samples"));
  f.dropped = static_cast<unsigned long long>(number(m["dropped_samples"], p, "dropped_samples"));
  f.samples = static_cast<unsigned long long>(number(m["samples"], p, "samples"));
  const YAML::Node corner = m["corner_energy"];
  if (corner && corner.IsMap() && corner["max_peak_to_track_mean"])
    f.worst_corner_peak_ratio = number(corner["max_peak_to_track_mean"], p, "corner_energy.max_peak_to_track_mean");
  const YAML::Node same = m["contour_error"] ? m["contour_error"]["same_instant"] : YAML::Node();
  const char* under[3] = {"share_under_10um", "share_under_20um", "share_under_30um"};
  for (int i = 0; i < 3; ++i)
  {
    auto share = [&](const char* kind) {
      const YAML::Node k = same ? same[kind] : YAML::Node();
      return k && k.IsMap() ? number(k[under[i]], p, std::string("contour_error.same_instant.") + kind) : 0.0;
    };
    f.mark_under_um[i] = share("mark");
    f.contour_under_um[i] = share("contour");
    f.hatch_under_um[i] = share("hatch");
  }
  return f;
}

std::vector<std::string> studySummaryColumns(const std::vector<CaseRecord>& cases)
{
  std::vector<std::string> columns = {"case", "job", "layer"};
  for (const auto& [key, value] : gridValues(cases.empty() ? "" : cases.front().grid_text))
    columns.push_back(key);
  for (const char* c :
       {"status", "error", "wall_s", "layer_time_s", "fill_rate_pct", "mark_under_10um_pct", "mark_under_20um_pct",
        "mark_under_30um_pct", "contour_under_10um_pct", "contour_under_20um_pct", "contour_under_30um_pct",
        "hatch_under_10um_pct", "hatch_under_20um_pct", "hatch_under_30um_pct", "peak_energy_jmm2",
        "worst_corner_peak_ratio", "laser_early_samples", "laser_late_samples", "dropped_samples"})
    columns.emplace_back(c);
  return columns;
}

std::size_t writeStudySummary(const std::string& dir, const std::vector<CaseRecord>& cases, std::string* html_body)
{
  const std::vector<std::string> columns = studySummaryColumns(cases);
  std::ostringstream csv;
  for (std::size_t i = 0; i < columns.size(); ++i)
    csv << (i ? "," : "") << columns[i];
  csv << "\n";
  std::vector<std::pair<const CaseRecord*, CaseFigures>> done;
  std::vector<const CaseRecord*> failed, pending;
  for (const CaseRecord& c : cases)
  {
    CaseFigures f;
    bool have = false;
    std::string error = c.error;
    if (c.state == CaseState::Done)
    {
      try
      {
        f = readCaseFigures((fs::path(caseResultsDir(dir, c.id)) / "metrics.yaml").string());
        have = true;
        done.emplace_back(&c, f);
      }
      catch (const std::exception& e)
      {
        error = e.what();
      }
    }
    else if (c.state == CaseState::Failed)
      failed.push_back(&c);
    else
      pending.push_back(&c);
    csv << csvField(c.id) << "," << csvField(fs::path(c.job).filename().string()) << ","
        << (c.layer >= 0 ? std::to_string(c.layer) : "");
    for (const auto& [key, value] : gridValues(c.grid_text))
      csv << "," << csvField(value);
    csv << "," << stateName(c.state) << "," << csvField(error) << ","
        << (c.wall_s >= 0.0 ? fixedText(c.wall_s, 3) : "");
    if (have)
    {
      csv << "," << sixDigitText(f.layer_time_s) << "," << percent(f.fill_rate);
      for (const double* shares : {f.mark_under_um, f.contour_under_um, f.hatch_under_um})
        for (int i = 0; i < 3; ++i)
          csv << "," << percent(shares[i]);
      csv << "," << sixDigitText(f.peak_energy_jmm2) << "," << sixDigitText(f.worst_corner_peak_ratio) << ","
          << f.laser_early << "," << f.laser_late << "," << f.dropped;
    }
    else
      csv << std::string(16, ',');
    csv << "\n";
  }
  writeFileWhole((fs::path(dir) / "summary.csv").string(), csv.str());

  // The page: counts, the worst cases by each figure, every case, every failure with its error; as Markdown
  // (summary.md) and as the body of summary.html (its plots are added when they are drawn).
  std::ostringstream md, html;
  std::ostringstream counts;
  counts << cases.size() << " cases: " << done.size() << " done, " << failed.size() << " failed, " << pending.size()
         << " pending.";
  md << "# Study summary\n\n"
     << counts.str() << " Figures per case in `summary.csv`; each case's results in `cases/<case>/`.\n\n";
  html << "<h1>Study summary</h1>\n<p>" << htmlEscape(counts.str())
       << " Figures per case in <code>summary.csv</code>; each case's results (and its report.html) in "
          "<code>cases/&lt;case&gt;/</code>.</p>\n";
  if (!done.empty())
  {
    std::vector<std::vector<std::string>> worst_rows;
    auto worst = [&](const char* what, auto value, bool low) {
      // Cases without the figure (NaN: no contour in the job; 0 corner ratio: no corner) are not ranked.
      const std::pair<const CaseRecord*, CaseFigures>* pick = nullptr;
      for (const auto& d : done)
      {
        const double v = value(d.second);
        if (std::isnan(v) || (!low && v == 0.0))
          continue;
        if (pick == nullptr || (low ? v < value(pick->second) : v > value(pick->second)))
          pick = &d;
      }
      if (pick != nullptr)
      {
        md << "- " << what << ": **" << pick->first->id << "** (" << sixDigitText(value(pick->second)) << ")\n";
        worst_rows.push_back({what, pick->first->id, sixDigitText(value(pick->second))});
      }
    };
    md << "## Worst cases\n\n";
    worst(
        "lowest fill rate [%]", [](const CaseFigures& f) { return 100.0 * f.fill_rate; }, true);
    worst(
        "lowest share of contour points under 10 um [%]",
        [](const CaseFigures& f) { return 100.0 * f.contour_under_um[0]; }, true);
    worst(
        "lowest share of hatch points under 10 um [%]",
        [](const CaseFigures& f) { return 100.0 * f.hatch_under_um[0]; }, true);
    worst(
        "lowest share of marked points under 10 um [%]",
        [](const CaseFigures& f) { return 100.0 * f.mark_under_um[0]; }, true);
    worst(
        "highest corner peak / track mean", [](const CaseFigures& f) { return f.worst_corner_peak_ratio; }, false);
    worst(
        "highest energy peak [J/mm^2]", [](const CaseFigures& f) { return f.peak_energy_jmm2; }, false);
    html << "<h2>Worst cases</h2>\n" << htmlTable({"figure", "case", "value"}, worst_rows, 2);
    const std::vector<std::string> header = {"case",
                                             "layer",
                                             "status",
                                             "wall [s]",
                                             "layer time [s]",
                                             "fill [%]",
                                             "contour <10/20/30 um [%]",
                                             "hatch <10 um [%]",
                                             "peak [J/mm^2]",
                                             "corner peak ratio",
                                             "laser early/late",
                                             "dropped"};
    std::vector<std::vector<std::string>> rows;
    for (const auto& [c, f] : done)
      rows.push_back(
          {c->id, c->layer >= 0 ? std::to_string(c->layer) : "", "done",
           c->wall_s >= 0.0 ? fixedText(c->wall_s, 2) : "", fixedText(f.layer_time_s, 4), percent(f.fill_rate),
           percent(f.contour_under_um[0]) + " / " + percent(f.contour_under_um[1]) + " / " +
               percent(f.contour_under_um[2]),
           percent(f.hatch_under_um[0]), sixDigitText(f.peak_energy_jmm2), fixedText(f.worst_corner_peak_ratio, 3),
           std::to_string(f.laser_early) + " / " + std::to_string(f.laser_late), std::to_string(f.dropped)});
    md << "\n## Cases\n\n|";
    for (const std::string& h : header)
      md << " " << h << " |";
    md << "\n|";
    for (std::size_t k = 0; k < header.size(); ++k)
      md << "---|";
    md << "\n";
    for (const auto& row : rows)
    {
      md << "|";
      for (const std::string& cell : row)
        md << " " << cell << " |";
      md << "\n";
    }
    html << "<h2>Cases</h2>\n" << htmlTable(header, rows, 3);
  }
  if (!failed.empty())
  {
    md << "\n## Failed cases\n\n";
    html << "<h2>Failed cases</h2>\n<ul>\n";
    for (const CaseRecord* c : failed)
    {
      md << "- **" << c->id << "** (exit " << c->exit_code << "): " << c->error << " — log: `logs/" << c->id
         << ".log`\n";
      html << "<li><b>" << htmlEscape(c->id) << "</b> (exit " << c->exit_code << "): " << htmlEscape(c->error)
           << " — log: <code>logs/" << htmlEscape(c->id) << ".log</code></li>\n";
    }
    html << "</ul>\n";
  }
  if (!pending.empty())
  {
    md << "\n## Pending cases\n\n";
    html << "<h2>Pending cases</h2>\n<ul>\n";
    for (const CaseRecord* c : pending)
    {
      md << "- " << c->id << "\n";
      html << "<li>" << htmlEscape(c->id) << "</li>\n";
    }
    html << "</ul>\n";
  }
  if (html_body != nullptr)
    *html_body = html.str();
  writeFileWhole((fs::path(dir) / "summary.md").string(), md.str());
  return done.size();
}
void writeStudySummaryPage(const std::string& dir, const std::string& html_body)
{
  std::string body = html_body;
  const std::pair<const char*, const char*> plots[] = {
      {"summary_layers.png", "Each figure across the layers (or job files) of the study"},
      {"summary_grid.png", "Each figure per grid combination"}};
  bool any = false;
  for (const auto& [name, caption] : plots)
  {
    const std::string png = readFileOrEmpty((fs::path(dir) / name).string());
    if (png.empty())
      continue;
    body += (any ? "" : "<h2>Plots</h2>\n") + htmlPngFigure(png, caption);
    any = true;
  }
  writeFileWhole((fs::path(dir) / "summary.html").string(), htmlPage("scanhead study summary", body));
}
}  // namespace scanhead
