/// \file results_writer.hpp
/// \brief Writes a run's results folder so that it never lies: the folder at the target path is
/// always either the previous run's, untouched, or this run's, complete (plots included); the one
/// exception says so itself: the energy node's result of a stalled job (`complete: false`).
///
/// How: the target is locked for the whole run (common/folder_lock: a second writer of the same
/// folder fails at once, naming the first); the files are written into a staging folder of this
/// run's own beside the target (common/staged_folder) and published by one rename (an exchange with
/// the previous folder) only after every file, the finisher's plots included, is written. Any
/// failure (a full disk, named as such; a plot script that fails or is killed; a stop request of
/// common/stop_request, i.e. SIGINT/SIGTERM in the tools) throws and removes the staging folder;
/// the staging folders of runs killed outright are removed by the next writer of the target.
///
/// Contents: metrics.yaml, config.yaml (the settings used), job.yaml, job_stats.yaml, job.png
/// (marks and jumps), trace.csv (decimated spot
/// stream), energy_map.png (colour map with a colour bar; scale in energy_map.yaml),
/// energy_map_16bit.png (linear, 0..peak) and energy_map.yaml (geometry and scale); then the
/// finisher's files (the plots); last report.html (report/results_report: the page to open or send,
/// every image embedded).
///
/// The files are independent: they are written side by side on a few threads (report/task_pool),
/// each by one task, so their bytes are those of a serial write whatever the thread count.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "scanhead/chain/chain_config.hpp"
#include "scanhead/chain/energy_stage.hpp"
#include "scanhead/common/folder_lock.hpp"
#include "scanhead/common/plot_hook.hpp"
#include "scanhead/job/scan_job.hpp"
#include "scanhead/metrics/run_metrics.hpp"

namespace scanhead
{
/// \brief Marker file that identifies a scanhead results folder (such a folder may be replaced).
constexpr const char* kResultsMarker = ".scanhead_results";

/// \brief Called on the complete staging folder just before it is published: the plot hook (the
/// tools and nodes pass plotFinisher() of src/tools/support/python_plots.hpp, or a PlotProcess, which
/// run scripts/plot_results.py), so the plots land in the folder with the data. A finisher that
/// cannot make its plots throws: the results are then not published.
using ResultsFinisher = PlotHook;

/// \brief Takes the lock of the results folder \p dir before a run (the tools: before the chain,
/// so that a second run on the same folder fails before it computes anything), checks that \p dir
/// may be replaced, and removes what killed writers left beside it (StagedFolder::removeStale).
/// \param[out] removed  if set, receives the stale folders removed (for a note to the user)
/// \throws FolderBusyError naming the holder if another process writes \p dir
/// \throws InputError if \p dir exists and is neither empty nor a previous results folder
FolderLock lockResultsFolder(const std::string& dir, std::vector<std::string>* removed = nullptr);

/// \brief Writes the results folder \p lock.folder() (the contents in the file comment), calling
/// \p finish (if set) on the complete staging folder before it is published.
/// \param[in] lock  from lockResultsFolder(), held until this returns
/// \param[in] data_written  if set, called with the staging folder (from a writing thread) as
/// soon as metrics.yaml, job.yaml and trace.csv are in it, while the images are still being
/// written: a plot process may start drawing what needs no image. \p finish is still called on
/// the complete folder.
/// \param[in] on_failure  if set, called when writing fails, before the staging folder is removed:
/// whatever data_written started must stop writing into it.
/// \throws InputError if a file cannot be written ("no space left on device writing <file>" when
/// the file system is full), StopRequested on a stop request (common/stop_request), and whatever
/// \p finish throws; the previous folder at the target is then unchanged and no staging folder is left
void writeResultsFolder(const FolderLock& lock, const RunMetrics& metrics, const EnergyStage& energy,
                        const ChainConfig& config, const Job& job, const ResultsFinisher& finish = {},
                        const PlotHook& data_written = {}, const std::function<void()>& on_failure = {});

/// \brief writeResultsFolder(lockResultsFolder(dir), ...): locks \p dir for the write only.
/// \throws FolderBusyError, InputError as lockResultsFolder() and the overload above
void writeResultsFolder(const std::string& dir, const RunMetrics& metrics, const EnergyStage& energy,
                        const ChainConfig& config, const Job& job, const ResultsFinisher& finish = {},
                        const PlotHook& data_written = {}, const std::function<void()>& on_failure = {});
}  // namespace scanhead
