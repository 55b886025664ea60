/// \file study_runner.hpp
/// \brief Running a study's cases as scanhead_run processes: one case (what a Slurm array task does), or all pending
/// cases on N local workers (the local backend) with a progress line. A case is its own process: a case that fails
/// or a worker that is killed ends only that case; its error and log are kept (study_folder.hpp).
#pragma once

#include <string>
#include <vector>

#include "scanhead/study/study_folder.hpp"

namespace scanhead
{
struct StudyRunOptions
{
  std::string scanhead_run;  ///< the executable (beside scanhead_study)
  std::string plots = "none";
  unsigned workers = 1;
  /// \brief Local backend with several workers: a case started while others wait runs on one thread (the cases
  /// fill the cores); the last ones keep their stream.threads, to use the cores the finished workers leave.
  bool one_thread_while_waiting = true;
  bool progress_tty = false;  ///< a terminal: one line rewritten; else a line every 10 %
};

/// \brief Runs case \p c now (scanhead_run --job … --config configs/<id>.yaml --out cases/<id> --plots … --quiet,
/// its output into logs/<id>.log) and records how it ended (status/<id>.yaml). \return true if it is done
bool runStudyCase(const std::string& dir, const CaseRecord& c, const StudyRunOptions& options);

/// \brief Runs \p cases (indices into \p records) on options.workers processes at once, printing progress (count,
/// failures, time left) to stderr; with several workers, cases started while others wait get stream.threads=1
/// (results are bit-identical for any thread count; config.yaml records the count used). \return the number that
/// failed
std::size_t runStudyLocally(const std::string& dir, const std::vector<CaseRecord>& records,
                            const std::vector<std::size_t>& cases, const StudyRunOptions& options);

/// \brief The scanhead tool \p name in the folder of this executable (/proc/self/exe).
std::string siblingExecutable(const std::string& name);
}  // namespace scanhead
