/// \file chain_fixture.hpp
/// \brief One job through the whole batch chain with the package's config and overrides: what
/// the core tests of the chain share.
#pragma once

#include <string>
#include <vector>

#include "scanhead/core/batch_chain.hpp"
#include "scanhead/core/config_io.hpp"
#include "scanhead/core/job_files.hpp"
#include "scanhead/core/job_io.hpp"
#include "scanhead/core/results_writer.hpp"

namespace scanhead::test_support
{
inline const std::string kConfig = std::string(SCANHEAD_SOURCE_DIR) + "/config/scanhead.yaml";

struct ChainRun
{
  RunMetrics metrics;
  std::vector<float> map;  ///< the energy map's pixels
  NcStats nc;              ///< what the NC measured
  double job_time_s = 0.0; ///< NC program duration [s]
};

/// \brief Runs \p job_spec (built-in or file) with config/scanhead.yaml and \p overrides; writes
/// its results folder (no plots) into \p results_dir unless it is empty.
inline ChainRun runJob(const std::string& job_spec, const std::vector<std::string>& overrides,
                       const std::string& results_dir = "")
{
  const ChainConfig config = loadChainConfig(kConfig, overrides);
  const OpticalModel optics = loadOpticalModel(config.optics);
  const Job job = loadJob(job_spec, config.cam);
  validateScanJob(job, config.optics.field_half_width_m);
  BatchChain chain(config, optics);
  ChainRun run;
  run.metrics = chain.run(job);
  run.map = chain.energy().map().toDense().data();
  run.nc = chain.nc().stats();
  run.job_time_s = chain.nc().pathDuration();
  if (!results_dir.empty())
    writeResultsFolder(results_dir, run.metrics, chain.energy(), config, job);
  return run;
}
}  // namespace scanhead::test_support
