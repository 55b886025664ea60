/// \file results_report.hpp
/// \brief report.html of a results folder: the one file to open or to send (issue 17).
///
/// Built from the run's metrics in memory and the files already in the folder (never by parsing
/// metrics.yaml again: a whole layer's corner list makes it megabytes), so it costs milliseconds whatever the
/// job: the headline figures with their units (energies, peak density in J/mm², fill rate, contour-error shares
/// by kind, laser timing, corner peaks), the corners with the highest energy peaks, every image of the folder
/// but the 16-bit data PNGs (embedded: the page is one self-contained file), then metrics.yaml (its part above
/// the corner list), config.yaml and job_stats.yaml folded at the end.
#pragma once

#include <string>

#include "scanhead/job/scan_job.hpp"
#include "scanhead/metrics/run_metrics.hpp"

namespace scanhead
{
/// \brief Corners listed in the report's table (the highest energy peaks; the count says how many there are).
constexpr std::size_t kReportCorners = 20;

/// \brief The report page of the results folder \p dir (its images and YAML files as written so far).
std::string resultsReportHtml(const std::string& dir, const RunMetrics& metrics, const Job& job);
}  // namespace scanhead
