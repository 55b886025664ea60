/// \file slurm_backend.hpp
/// \brief A study on a Slurm cluster: one job array (one task per case: `scanhead_study run-case DIR INDEX`, which
/// writes the same case folders as the local backend) and a collection job that runs when the array has ended
/// (`--dependency=afterany`). Needs a filesystem shared by the submit host and the nodes (DIR and the executables at
/// the same paths), as any Slurm array of file-based jobs.
#pragma once

#include <string>
#include <vector>

namespace scanhead
{
struct SlurmOptions
{
  std::string study_exe;       ///< scanhead_study (absolute: the nodes run it)
  unsigned max_running = 0;    ///< tasks running at once (--array=…%M); 0: as many as Slurm allows
  unsigned cpus_per_task = 2;  ///< scanhead_run runs the chain on two threads (stream.threads)
  std::string partition;       ///< "": the cluster's default
  std::string time_limit;      ///< per task, Slurm's format ("30:00"); "": the partition's default
  bool wait = false;           ///< block until the collection job has ended
};

/// \brief "0-3,5,7-9" for the sorted \p indices (Slurm's --array syntax).
std::string slurmIndexList(const std::vector<std::size_t>& indices);

/// \brief The batch script of the array over \p indices (what --dry-run prints).
std::string slurmArrayScript(const std::string& dir, const std::vector<std::size_t>& indices,
                             const SlurmOptions& options);

/// \brief Writes DIR/slurm_array.sh, submits it with sbatch, then the collection job after it.
/// \return the array's job id. \throws InputError naming sbatch's message if a submission fails
std::string submitSlurmStudy(const std::string& dir, const std::vector<std::size_t>& indices,
                             const SlurmOptions& options);
}  // namespace scanhead
