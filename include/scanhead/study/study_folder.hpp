/// \file study_folder.hpp
/// \brief A study's folder: what is in it and what state each case is in. Every file is written whole (a staging
/// file renamed into place), so a study killed at any moment leaves finished cases finished and nothing half-written.
///
///   DIR/study.yaml          the study file as run (a copy)
///   DIR/cases.tsv           index, id, job, layer and grid values of every case: what a Slurm array task reads
///   DIR/configs/<id>.yaml   the settings of the case (scanhead_run --config)
///   DIR/cases/<id>/         its results folder, exactly what scanhead_run writes (published by one rename)
///   DIR/status/<id>.yaml    how its last run ended: status (done | failed), exit code, wall time, error
///   DIR/logs/<id>.log       what its run printed
///   DIR/summary.csv, summary.md, summary_*.png   what `scanhead_study collect` writes
#pragma once

#include <string>
#include <vector>

#include "scanhead/study/study_cases.hpp"

namespace scanhead
{
/// \brief How a case stands.
enum class CaseState
{
  Pending,  ///< never run, or its run was killed before it ended
  Done,     ///< its results folder is published
  Failed    ///< its last run ended with an error (kept in status/<id>.yaml)
};

/// \brief A case as read back from the folder.
struct CaseRecord
{
  std::size_t index = 0;
  std::string id, job, grid_text;  ///< grid_text: "key=value;key=value"
  int layer = -1;
  CaseState state = CaseState::Pending;
  int exit_code = 0;
  double wall_s = -1.0;  ///< < 0: not known (a case published by a run killed before its status was written)
  std::string error;     ///< the failed run's error line
};

/// \brief Writes study.yaml, cases.tsv and configs/ for \p cases (atomically, each file whole). Results, status
/// and logs of earlier runs stay: a case keeps its id as long as its job and settings do.
void writeStudyPlan(const std::string& dir, const std::string& study_text, const std::vector<StudyCase>& cases);

/// \brief The cases of cases.tsv with their state. \throws InputError if DIR is not a study folder
std::vector<CaseRecord> readStudyCases(const std::string& dir);

/// \brief Records how a case's run ended (status/<id>.yaml, written whole).
void writeCaseStatus(const std::string& dir, const std::string& id, bool done, int exit_code, double wall_s,
                     const std::string& error);

/// \brief Paths of a case's files.
std::string caseResultsDir(const std::string& dir, const std::string& id);
std::string caseConfigPath(const std::string& dir, const std::string& id);
std::string caseLogPath(const std::string& dir, const std::string& id);

/// \brief The last line of \p log that says what went wrong ("…: error: …"), else its last non-empty line.
std::string errorLineOf(const std::string& log);

/// \brief Writes \p text to \p path through a staging file renamed into place.
void writeFileWhole(const std::string& path, const std::string& text);
}  // namespace scanhead
