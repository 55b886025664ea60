/// \file study_estimate.cpp
/// \brief A study's time before it runs (study_estimate.hpp).
#include "scanhead/study/study_estimate.hpp"

#include <map>

#include "scanhead/chain/config_io.hpp"
#include "scanhead/chain/run_plan.hpp"
#include "scanhead/common/number_text.hpp"
#include "scanhead/job/job_files.hpp"
#include "scanhead/optics/optics_loading.hpp"

namespace scanhead
{
std::string durationText(double seconds)
{
  if (seconds < 90.0)
    return fixedText(seconds, 0) + " s";
  if (seconds < 5400.0)
    return fixedText(seconds / 60.0, 1) + " min";
  return fixedText(seconds / 3600.0, 1) + " h";
}

StudyEstimate estimateStudy(const std::vector<StudyCase>& cases, const std::vector<std::size_t>& todo)
{
  StudyEstimate estimate;
  struct PerJob
  {
    RunPlan plan;                      ///< of the job (a layered file: of its first layer)
    std::vector<double> layer_path_s;  ///< a layered file: every layer's path time (its survey)
    bool ok = false;
  };
  std::map<std::string, PerJob> per_job;  // one plan per job (file or spec), with the first case's settings
  for (const std::size_t k : todo)
  {
    const StudyCase& c = cases[k];
    auto it = per_job.find(c.job);
    if (it == per_job.end())
    {
      PerJob p;
      try
      {
        // A layered file: its first layer is planned, the others from their path time (the reader's survey), so a
        // build of any size costs one layer's memory here.
        ChainConfig config = chainConfigFromFlat(flattenYaml(c.config_yaml, c.id));
        config.cam.layer = c.layer >= 0 ? 0 : config.cam.layer;
        const Job job = loadJob(c.job, config.cam);
        p = {planRun(config, job, loadOpticalModel(config.optics)), job.file.layer_path_s, true};
      }
      catch (const std::exception&)
      {
        // The case will fail with the reader's or the plan's message; it costs nothing here.
      }
      it = per_job.emplace(c.job, p).first;
    }
    const PerJob& p = it->second;
    if (!p.ok)
    {
      ++estimate.unplanned;
      continue;
    }
    // Layer k: the NC program lasts the first layer's times the path-time ratio (accelerations and holds in the
    // same proportion); the filter delay and tail are the same; the wall time is the fixed setup plus the
    // per-sample part, in proportion to the machine time.
    const std::size_t layer = static_cast<std::size_t>(std::max(0, c.layer));
    const double ratio = c.layer >= 0 && layer < p.layer_path_s.size() && p.layer_path_s[0] > 0.0
                             ? p.layer_path_s[layer] / p.layer_path_s[0]
                             : 1.0;
    const RunPlan& first = p.plan;
    const double machine_s = first.machine_time_s + first.program_duration_s * (ratio - 1.0);
    estimate.machine_time_s += machine_s;
    estimate.wall_time_s +=
        first.setup_wall_s + (first.wall_time_s - first.setup_wall_s) *
                                 (first.machine_time_s > 0.0 ? machine_s / first.machine_time_s : 1.0);
  }
  return estimate;
}
}  // namespace scanhead
