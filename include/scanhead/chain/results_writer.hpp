/// \file results_writer.hpp
/// \brief Writes a run's results folder atomically: built in a sibling temporary folder and
/// renamed into place, so a failed run never leaves a half-written folder.
///
/// Contents: metrics.yaml, config.yaml (the settings used), job.yaml, job_stats.yaml, job.png
/// (marks and jumps), trace.csv (decimated spot
/// stream), energy_map.png (colour map with a colour bar; scale in energy_map.yaml),
/// energy_map_16bit.png (linear, 0..peak) and energy_map.yaml (geometry and scale).
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "scanhead/chain/chain_config.hpp"
#include "scanhead/chain/energy_stage.hpp"
#include "scanhead/metrics/run_metrics.hpp"
#include "scanhead/job/scan_job.hpp"

namespace scanhead
{
/// \brief Marker file that identifies a scanhead results folder (such a folder may be replaced).
constexpr const char* kResultsMarker = ".scanhead_results";

/// \brief Called on the complete temporary folder just before it is renamed into place (e.g. plots).
using ResultsFinisher = std::function<void(const std::string& tmp_dir)>;

/// \throws InputError if \p dir exists and is neither empty nor a previous results folder
void writeResultsFolder(const std::string& dir, const RunMetrics& metrics, const EnergyStage& energy,
                        const ChainConfig& config, const Job& job, const ResultsFinisher& finish = {});

/// \brief A finisher that runs scripts/plot_results.py on the folder with the system python3;
/// a missing python3-matplotlib only loses the plots (a warning on stderr), never the results.
ResultsFinisher plotFinisher();

/// \brief Runs a package script (path resolved with resolvePackagePath) with the system python3
/// and \p arguments; false, with a warning on stderr, if it fails (plots are never essential).
bool runPythonScript(const std::string& script, const std::vector<std::string>& arguments);
}  // namespace scanhead
