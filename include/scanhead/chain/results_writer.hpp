/// \file results_writer.hpp
/// \brief Writes a run's results folder atomically: built in a sibling temporary folder and
/// renamed into place, so a failed run never leaves a half-written folder.
///
/// Contents: metrics.yaml, config.yaml (the settings used), job.yaml, job_stats.yaml, job.png
/// (marks and jumps), trace.csv (decimated spot
/// stream), energy_map.png (colour map with a colour bar; scale in energy_map.yaml),
/// energy_map_16bit.png (linear, 0..peak) and energy_map.yaml (geometry and scale); then the
/// finisher's files (the plots).
///
/// The files are independent: they are written side by side on a few threads (report/task_pool),
/// each by one task, so their bytes are those of a serial write whatever the thread count.
#pragma once

#include <functional>
#include <string>

#include "scanhead/chain/chain_config.hpp"
#include "scanhead/chain/energy_stage.hpp"
#include "scanhead/common/plot_hook.hpp"
#include "scanhead/job/scan_job.hpp"
#include "scanhead/metrics/run_metrics.hpp"

namespace scanhead
{
/// \brief Marker file that identifies a scanhead results folder (such a folder may be replaced).
constexpr const char* kResultsMarker = ".scanhead_results";

/// \brief Called on the complete temporary folder just before it is renamed into place: the
/// plot hook (the tools and nodes pass plotFinisher() of src/tools/support/python_plots.hpp, which
/// runs scripts/plot_results.py), so the plots land in the folder with the data.
using ResultsFinisher = PlotHook;

/// \brief Writes the results folder \p dir (the contents in the file comment), calling \p finish
/// (if set) on the complete temporary folder before the rename.
/// \param[in] data_written  if set, called with the temporary folder (from a writing thread) as
/// soon as metrics.yaml, job.yaml and trace.csv are in it, while the images are still being
/// written: a plot process may start drawing what needs no image. \p finish is still called on
/// the complete folder.
/// \param[in] on_failure  if set, called when writing fails, before the temporary folder is removed:
/// whatever data_written started must stop writing into it.
/// \throws InputError if \p dir exists and is neither empty nor a previous results folder
void writeResultsFolder(const std::string& dir, const RunMetrics& metrics, const EnergyStage& energy,
                        const ChainConfig& config, const Job& job, const ResultsFinisher& finish = {},
                        const PlotHook& data_written = {}, const std::function<void()>& on_failure = {});
}  // namespace scanhead
