/// \file results_report.cpp
/// \brief report.html of a results folder (results_report.hpp).
#include "scanhead/report/results_report.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <numeric>

#include "scanhead/common/number_text.hpp"
#include "scanhead/common/text_file.hpp"
#include "scanhead/report/html_page.hpp"

namespace scanhead
{
namespace
{
namespace fs = std::filesystem;

/// \brief \p value with \p digits significant digits ("-" for NaN).
std::string num(double value, int digits = 4)
{
  return std::isnan(value) ? "-" : significantText(value, digits);
}

std::string count(std::uint64_t value)
{
  return std::to_string(value);
}

std::string percent(double share)
{
  return std::isnan(share) ? "-" : num(100.0 * share, 4) + " %";
}

constexpr double kJpm2ToJpmm2 = 1e-6;  ///< 1 J/m² = 1e-6 J/mm²
constexpr int kZoomWidthPx = 400;      ///< narrower pictures (a corner's crop) are shown enlarged

/// The images in reading order: the energy first, then the quality figures, then anything else the folder has
/// (thermal views); the 16-bit PNGs are data for programs, not pictures.
std::vector<std::pair<std::string, std::string>> reportImages(const fs::path& dir)
{
  const std::vector<std::pair<std::string, std::string>> known = {
      {"energy_map_plot.png", "Energy density on the work plane [J/mm²], the commanded path where it does not hide it"},
      {"energy_map.png", "Energy map, colour bar in J/mm², scale bar in mm"},
      {"crops/worst_corner.png", "Energy around the corner with the highest peak, full resolution [J/mm²]"},
      {"corner_zoom.png", "The corner with the highest energy peak: commanded, setpoint and actual paths"},
      {"quality.png", "Layer quality: contour error, fill rate, speed"},
      {"contour_error.png", "Contour error along the job"},
      {"speed.png", "Actual / programmed speed"},
      {"job.png", "The job: marks and jumps"}};
  std::vector<std::pair<std::string, std::string>> images;
  for (const auto& [name, caption] : known)
    if (fs::exists(dir / name))
      images.emplace_back(name, caption);
  std::vector<std::string> others;
  std::error_code ec;
  for (const auto& sub : {fs::path(), fs::path("crops")})
    for (fs::directory_iterator it(dir / sub, ec), end; !ec && it != end; it.increment(ec))
    {
      const std::string name = (sub / it->path().filename()).string();
      const bool png = it->path().extension() == ".png";
      const bool data16 = name.size() > 10 && name.compare(name.size() - 10, 10, "_16bit.png") == 0;
      const bool listed = std::any_of(known.begin(), known.end(), [&](const auto& k) { return k.first == name; });
      if (png && !data16 && !listed)
        others.push_back(name);
    }
  std::sort(others.begin(), others.end());  // directory order is not deterministic
  for (const std::string& name : others)
    images.emplace_back(name,
                        name.rfind("crops/", 0) == 0 ? "Crop " + name.substr(6) + " of the energy map [J/mm²]" : name);
  return images;
}

std::string summaryTable(const RunMetrics& m)
{
  std::vector<std::vector<std::string>> rows = {
      {"machine time", num(m.duration_s, 6), "s", "samples × Ts"},
      {"layer time", num(m.quality.layer_time_s, 6), "s", "the NC program, holds included"},
      {"samples", count(m.samples), "", m.dropped_samples ? count(m.dropped_samples) + " dropped" : "none dropped"},
      {"laser on", num(m.laser_on_time_s, 6), "s", ""},
      {"commanded energy", num(m.commanded_energy_j, 6), "J", "Σ P·Ts"},
      {"deposited energy", num(m.deposited_energy_j, 6), "J",
       "on the map; " + num(m.energy_outside_map_j, 3) + " J outside"},
      {"peak energy density", num(m.peak_energy_density_jpm2 * kJpm2ToJpmm2, 4), "J/mm²", ""},
      {"fill rate", percent(m.quality.fill_rate), "",
       count(m.quality.fill_cells_reached) + " of " + count(m.quality.fill_cells_to_fill) + " cells of " +
           num(m.quality.fill_pitch_m * 1e6, 3) + " µm"},
      {"laser early / late", count(m.laser_early_samples) + " / " + count(m.laser_late_samples), "samples",
       num(m.laser_misplaced_energy_j, 3) + " J misplaced"},
      {"laser off the path", count(m.laser_off_path_samples), "samples",
       "farthest " + num(m.laser_max_off_path_m * 1e6, 3) + " µm"}};
  if (m.track_measured)
  {
    rows.push_back({"track energy (median)", num(m.track_median_jpm2 * kJpm2ToJpmm2, 4), "J/mm²",
                    "peak / median " + num(m.track_peak_to_median, 3)});
  }
  if (!m.corners.empty())
    rows.push_back(
        {"corner peak / track mean", num(m.corner_peak_to_track_mean, 3), "",
         "worst " + num(m.corner_peak_to_track_mean_max, 3) + ", " + std::to_string(m.corners.size()) + " corners"});
  if (!std::isnan(m.quality.mark_speed_mean_ratio))
    rows.push_back({"mark speed / programmed", num(m.quality.mark_speed_mean_ratio, 4), "", "mean, laser-on marks"});
  return htmlTable({"figure", "value", "unit", "note"}, rows, 1, 2);
}

std::string contourTable(const ContourErrorSplit& split)
{
  std::vector<std::vector<std::string>> rows;
  const std::pair<const char*, const ContourErrorStats*> kinds[] = {
      {"marks", &split.mark}, {"contours", &split.contour}, {"hatches", &split.hatch}, {"jumps", &split.jump}};
  for (const auto& [name, stats] : kinds)
  {
    if (stats->count() == 0)
      continue;
    rows.push_back({name, count(stats->count()), percent(stats->shareUnder(10e-6)), percent(stats->shareUnder(20e-6)),
                    percent(stats->shareUnder(30e-6)), num(stats->mean() * 1e6, 3), num(stats->max() * 1e6, 3)});
  }
  return htmlTable({"points", "count", "< 10 µm", "< 20 µm", "< 30 µm", "mean [µm]", "max [µm]"}, rows);
}

std::string cornerTable(const RunMetrics& m)
{
  std::vector<std::size_t> order(m.corners.size());
  std::iota(order.begin(), order.end(), 0);
  const std::size_t shown = std::min(kReportCorners, order.size());
  // The highest energy peaks first; ties in job order (stable), so the table is the same every run.
  std::partial_sort(order.begin(), order.begin() + static_cast<std::ptrdiff_t>(shown), order.end(),
                    [&](std::size_t a, std::size_t b) {
                      return m.corners[a].energy_peak_jpm2 != m.corners[b].energy_peak_jpm2
                                 ? m.corners[a].energy_peak_jpm2 > m.corners[b].energy_peak_jpm2
                                 : a < b;
                    });
  std::vector<std::vector<std::string>> rows;
  for (std::size_t k = 0; k < shown; ++k)
  {
    const CornerReport& c = m.corners[order[k]];
    rows.push_back({std::to_string(c.corner.polyline) + "/" + std::to_string(c.corner.vertex),
                    num(c.corner.point.x() * 1e3, 5), num(c.corner.point.y() * 1e3, 5),
                    num(c.corner.angle_rad * 180.0 / M_PI, 4), num(c.corner.speed_mps, 4),
                    num(c.actual.min_speed_mps, 4), num(c.actual.max_contour_error_m * 1e6, 4),
                    num(c.theory.max_contour_error_m * 1e6, 4), num(c.energy_peak_jpm2 * kJpm2ToJpmm2, 4),
                    m.track_mean_jpm2 > 0.0 ? num(c.energy_peak_jpm2 / m.track_mean_jpm2, 3) : "-"});
  }
  return htmlTable({"polyline/vertex", "x [mm]", "y [mm]", "turn [°]", "speed [m/s]", "min speed [m/s]",
                    "contour error [µm]", "theory [µm]", "energy peak [J/mm²]", "peak / track mean"},
                   rows);
}
}  // namespace

std::string resultsReportHtml(const std::string& dir, const RunMetrics& m, const Job& job)
{
  const fs::path folder(dir);
  // The file's name, not its path: the same job gives the same page wherever it was read from.
  const std::string source = job.source.substr(job.source.find_last_of('/') + 1);
  std::string body = "<h1>scanhead results: " + htmlEscape(m.job_name) + "</h1>\n<p>Job <code>" + htmlEscape(source) +
                     "</code>: " + std::to_string(job.polylines.size()) + " polylines, " + num(m.duration_s, 5) +
                     " s of machine time.";
  if (!m.job_placement.empty())
    body += " Placed on the field: <code>" + htmlEscape(m.job_placement) + "</code>.";
  body += "</p>\n";
  if (!m.complete)
    body += "<p class=\"warn\">Incomplete: the stream stopped at sample " + count(m.stream_gap.next_sample) + " of " +
            count(m.stream_gap.total_samples) + " (" + htmlEscape(m.stream_gap.streams) + ").</p>\n";
  for (const std::string& warning : m.warnings)
    body += "<p class=\"warn\">" + htmlEscape(warning) + "</p>\n";

  body += "<h2>Summary</h2>\n" + summaryTable(m);
  body += "<h2>Contour error (same instant, THESIS §2.5.3.1)</h2>\n" + contourTable(m.quality.same_instant);
  if (m.quality.nearest_measured)
    body += "<h2>Contour error (nearest path)</h2>\n" + contourTable(m.quality.nearest_path);
  if (!m.corners.empty())
    body += "<h2>Corners: the " + std::to_string(std::min(kReportCorners, m.corners.size())) +
            " highest energy peaks of " + std::to_string(m.corners.size()) + "</h2>\n" + cornerTable(m);

  body += "<h2>Images</h2>\n";
  for (const auto& [name, caption] : reportImages(folder))
    body += htmlPngFigure(readFileOrEmpty((folder / name).string()), caption, kZoomWidthPx);

  body += "<h2>Files</h2>\n";
  std::string metrics_yaml = readFileOrEmpty((folder / "metrics.yaml").string());
  const std::size_t corners_at = metrics_yaml.find("\ncorners:");
  if (corners_at != std::string::npos)
    metrics_yaml.resize(corners_at + 1);  // the corner list: the table above has the worst ones
  body += htmlDetails("metrics.yaml" + std::string(corners_at != std::string::npos ? " (without the corner list)" : ""),
                      metrics_yaml);
  body += htmlDetails("config.yaml (the settings of this run)", readFileOrEmpty((folder / "config.yaml").string()));
  body += htmlDetails("job_stats.yaml", readFileOrEmpty((folder / "job_stats.yaml").string()));
  return htmlPage("scanhead: " + m.job_name, body);
}
}  // namespace scanhead
