#include "scanhead/core/batch_chain.hpp"

#include <fstream>

#include "scanhead/core/optical_defects.hpp"

namespace scanhead
{
BatchChain::BatchChain(const ChainConfig& config, const OpticalModel& optics)
  : config_(config), optics_(optics), nc_(config.nc, resolveRecipe(config.recipe), optics, &config.servo), servo_(config.servo, config.nc.period_s), optical_stage_(optics)
{
}

RunMetrics BatchChain::run(const Job& job, const ProgressCallback& progress)
{
  nc_.start(job);
  energy_ = std::make_unique<EnergyStage>(config_, job, nc_);
  while (!nc_.done())
  {
    const NcOutput nc = nc_.process(config_.stream.chunk_samples);
    if (nc.setpoint.first_index == 0 && !nc.setpoint.samples.empty())
      servo_.reset(nc.setpoint.samples.front().position);  // at rest where the job starts
    const JointChunk joints = servo_.process(nc.setpoint);
    energy_->process(optical_stage_.process(nc.setpoint, joints, nc.laser));
    if (progress)
      progress(nc.setpoint.endIndex(), nc_.totalSamples());
  }
  return energy_->finish();
}

std::string resolvePackagePath(const std::string& path)
{
  if (path.empty() || path.front() == '/' || std::ifstream(path).good())
    return path;
  for (const std::string& root : {std::string(SCANHEAD_SHARE_DIR), std::string(SCANHEAD_SOURCE_DIR)})
  {
    const std::string candidate = root + "/" + path;
    if (std::ifstream(candidate).good())
      return candidate;
  }
  return path;
}

OpticalModel loadOpticalModel(const OpticsConfig& config)
{
  // Through the URDF text of the defective machine, as the graph reads it from robot_description:
  // the same parser on the same numbers, so the batch runner and the graph are bit-identical.
  const std::string path = resolvePackagePath(config.urdf_path);
  return OpticalModel(geometryFromUrdf(urdfWithDefects(readUrdfFile(path), loadDefects(config), path), path), config);
}

DefectSet loadDefects(const OpticsConfig& config)
{
  const std::string& spec = config.defects;
  const bool file = spec.size() > 5 && (spec.compare(spec.size() - 5, 5, ".yaml") == 0 ||
                                        spec.compare(spec.size() - 4, 4, ".yml") == 0);
  return defectSetByName(file ? resolvePackagePath(spec) : spec);
}
}  // namespace scanhead
