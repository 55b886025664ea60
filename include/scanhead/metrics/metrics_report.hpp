/// \file metrics_report.hpp
/// \brief RunMetrics as metrics.yaml (full precision, so identical runs give identical files)
/// and as the human-readable results table.
#pragma once

#include <string>

#include "scanhead/metrics/run_metrics.hpp"
#include "scanhead/nc/nc_config.hpp"
#include "scanhead/nc/nc_stats.hpp"

namespace scanhead
{
std::string metricsToYaml(const RunMetrics& metrics);
std::string metricsTable(const RunMetrics& metrics);

/// \brief What the NC measured on Q_filt2 while it ran (max acceleration and jerk against the
/// limits), one line; the NC node logs it, scanhead_run prints it.
std::string ncLimitsLine(const NcStats& stats, const NcConfig& config);
}  // namespace scanhead
