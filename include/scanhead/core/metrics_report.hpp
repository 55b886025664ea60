/// \file metrics_report.hpp
/// \brief RunMetrics as metrics.yaml (full precision, so identical runs give identical files)
/// and as the human-readable results table.
#pragma once

#include <string>

#include "scanhead/core/run_metrics.hpp"

namespace scanhead
{
std::string metricsToYaml(const RunMetrics& metrics);
std::string metricsTable(const RunMetrics& metrics);
}  // namespace scanhead
