/// \file study_summary.hpp
/// \brief What a build engineer reads of a study: one row per case (summary.csv), the same as a page
/// (summary.md) with the failures and the worst layers named, and as summary.html with the study's plots
/// embedded (report/html_page: one file to open or send).
#pragma once

#include <string>
#include <vector>

#include "scanhead/study/study_folder.hpp"

namespace scanhead
{
/// \brief A finished case's layer figures, from its metrics.yaml.
struct CaseFigures
{
  double layer_time_s = 0.0;
  double fill_rate = 0.0;
  /// same-instant contour error shares under 10/20/30 µm of the marked points, then of the contours and hatches
  double mark_under_um[3] = {0, 0, 0}, contour_under_um[3] = {0, 0, 0}, hatch_under_um[3] = {0, 0, 0};
  double peak_energy_jmm2 = 0.0;         ///< peak of the energy map [J/mm²]
  double worst_corner_peak_ratio = 0.0;  ///< largest corner peak / the track's mean level
  double commanded_energy_j = 0.0;
  unsigned long long laser_early = 0, laser_late = 0, dropped = 0, samples = 0;
};

/// \brief Reads the figures of a results folder's metrics.yaml (only its head: the corner list is not parsed).
/// \throws InputError if the file cannot be read or lacks a figure
CaseFigures readCaseFigures(const std::string& metrics_path);

/// \brief Column names of summary.csv, in order.
std::vector<std::string> studySummaryColumns(const std::vector<CaseRecord>& cases);

/// \brief Writes DIR/summary.csv and DIR/summary.md for \p cases (their figures read from their folders).
/// \param[out] html_body if set, the same as HTML (for writeStudySummaryPage once the plots are drawn)
/// \return the number of cases with figures
std::size_t writeStudySummary(const std::string& dir, const std::vector<CaseRecord>& cases,
                              std::string* html_body = nullptr);

/// \brief Writes DIR/summary.html: \p html_body (from writeStudySummary) and the plots the folder has
/// (summary_layers.png, summary_grid.png), embedded.
void writeStudySummaryPage(const std::string& dir, const std::string& html_body);
}  // namespace scanhead
