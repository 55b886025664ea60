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
  struct PerCase
  {
    double machine_s = 0.0, wall_s = 0.0;
    bool ok = false;
  };
  std::map<std::string, PerCase> per_job;  // one plan per job (file or spec), with the first case's settings
  for (const std::size_t k : todo)
  {
    const StudyCase& c = cases[k];
    auto it = per_job.find(c.job);
    if (it == per_job.end())
    {
      PerCase p;
      try
      {
        ChainConfig config = chainConfigFromFlat(flattenYaml(c.config_yaml, c.id));
        config.cam.layer = c.layer >= 0 ? -1 : config.cam.layer;  // a layered file: all its layers at once
        const Job job = loadJob(c.job, config.cam);
        const RunPlan plan = planRun(config, job, loadOpticalModel(config.optics));
        const double share = c.layer >= 0 ? 1.0 / static_cast<double>(std::max<std::size_t>(1, job.file_layers)) : 1.0;
        p = {plan.machine_time_s * share, plan.wall_time_s * share, true};
      }
      catch (const std::exception&)
      {
        // The case will fail with the reader's or the plan's message; it costs nothing here.
      }
      it = per_job.emplace(c.job, p).first;
    }
    if (!it->second.ok)
      ++estimate.unplanned;
    estimate.machine_time_s += it->second.machine_s;
    estimate.wall_time_s += it->second.wall_s;
  }
  return estimate;
}
}  // namespace scanhead
