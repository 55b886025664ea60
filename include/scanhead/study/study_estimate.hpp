/// \file study_estimate.hpp
/// \brief How long a study's cases will take, before they run: the run plan's wall-time estimate (run_plan.hpp:
/// the development VM's measured rates, ×0.5–2) of every job; of a layered file the first layer is planned and every
/// other layer's NC program taken as the first's times their path-time ratio (the reader's survey, file_survey.hpp),
/// so the estimate holds one layer in memory whatever the build; each grid combination is assumed to cost what the
/// first does.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "scanhead/study/study_cases.hpp"

namespace scanhead
{
struct StudyEstimate
{
  double machine_time_s = 0.0;  ///< Σ the cases' machine time [s]
  double wall_time_s = 0.0;     ///< Σ the cases' estimated chain wall time on one worker [s] (×0.5–2)
  std::size_t unplanned = 0;    ///< cases whose job could not be read (they will fail)
};

/// \brief The estimate of \p cases[k] for k in \p todo.
StudyEstimate estimateStudy(const std::vector<StudyCase>& cases, const std::vector<std::size_t>& todo);

/// \brief "12 s", "3.4 min", "2.1 h".
std::string durationText(double seconds);
}  // namespace scanhead
