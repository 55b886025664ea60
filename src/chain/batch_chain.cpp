#include "scanhead/chain/batch_chain.hpp"

#include <cstdio>
#include <exception>
#include <new>
#include <thread>

#include "scanhead/common/bounded_queue.hpp"
#include "scanhead/common/errors.hpp"
#include "scanhead/common/number_text.hpp"

namespace scanhead
{
namespace
{
/// Spot chunks in flight between the two threads: enough to absorb the jitter of either side,
/// few enough that memory stays small (4 × 1000 samples × 88 B).
constexpr std::size_t kQueuedChunks = 4;

void printWarning(const std::string& warning)
{
  std::fprintf(stderr, "warning: %s\n", warning.c_str());
}

/// The settings that size what \p stage allocates, for the out-of-memory message.
std::string outOfMemoryText(const std::string& job, const std::string& stage, const RunPlan& plan)
{
  std::string text = job + "out of memory in " + stage;
  if (plan.memory.total() > 0.0)
  {
    double part = 0.0;
    const std::string largest = plan.memory.largestPart(&part);
    text += " (the plan estimated " + significantText(plan.memory.total() / 1e6, 4) + " MB, the largest part " +
            largest + ": " + significantText(part / 1e6, 4) + " MB)";
  }
  return text +
         "; what grows with the settings: stream.chunk_samples, nc.fir_t1_s/nc.fir_t2_s against nc.period_s, "
         "nc.igt.table_nodes, energy.pixel_m, energy.tile_cache_bytes, energy.contour_max_samples, "
         "energy.track_max_samples, thermal.window_m/thermal.cell_m; lower limits.max_memory_fraction so the "
         "plan refuses such runs before they start";
}
}  // namespace

BatchChain::BatchChain(const ChainConfig& config, const OpticalModel& optics)
try : config_(config), optics_model_(optics), warn_(printWarning), nc_(config, optics), servo_(config.servo),
    optics_(optics), energy_(config)
{
}
catch (const std::bad_alloc&)
{
  throw ConfigError(
      outOfMemoryText("", "building the stages (the NC's correction tables: nc.igt.table_nodes)", RunPlan()));
}

SpotChunk BatchChain::nextSpotChunk()
{
  const NcOutput nc = nc_.process(config_.stream.chunk_samples);
  const JointChunk joints = servo_.process(nc.setpoint);
  return optics_.process({nc.setpoint, joints, nc.laser});
}

RunMetrics BatchChain::run(const Job& job, const ProgressCallback& progress)
{
  // Planned before anything that grows with the job is allocated (the plan itself is analytic).
  plan_ = RunPlan();
  plan_ = planRun(config_, job, optics_model_);
  enforceRunLimits(plan_, config_.limits, physicalMemoryBytes());
  return run(job, plan_, progress);
}

RunMetrics BatchChain::run(const Job& job, const RunPlan& plan, const ProgressCallback& progress)
{
  if (&plan != &plan_)
    plan_ = plan;
  if (warn_)
    for (const std::string& warning : plan_.warnings)
      warn_(warning);
  RunMetrics metrics;
  try
  {
    metrics = runPlanned(job, progress);
  }
  catch (const std::bad_alloc&)
  {
    throw ConfigError(
        outOfMemoryText("job '" + job.name + "': ", "the chain (NC -> servo -> optics -> energy)", plan_));
  }
  metrics.warnings = plan_.warnings;
  return metrics;
}

RunMetrics BatchChain::runPlanned(const Job& job, const ProgressCallback& progress)
{
  nc_.reset(job);
  const PlannedJob planned{job, nc_.plan()};
  servo_.reset({nc_.plan().period_s});
  optics_.reset({});
  energy_.reset(planned);
  const std::uint64_t total = nc_.plan().total_samples;
  auto consume = [&](const SpotChunk& spots) {
    energy_.process(spots);
    if (progress)
      progress(spots.endIndex(), total);
  };
  if (config_.stream.threads < 2)
  {
    while (!nc_.done())
      consume(nextSpotChunk());
    return energy_.finish();
  }
  // Two threads: NC → servo → optics on a producer thread, the energy stage on this one. Each side
  // handles the chunks in stream order, so the results do not depend on the scheduling.
  BoundedQueue<SpotChunk> queue(kQueuedChunks);
  std::exception_ptr producer_error;
  std::thread producer([&] {
    try
    {
      while (!nc_.done())
        if (!queue.push(nextSpotChunk()))
          return;  // the consumer gave up
    }
    catch (...)
    {
      producer_error = std::current_exception();
    }
    queue.close();
  });
  try
  {
    while (std::optional<SpotChunk> spots = queue.pop())
      consume(*spots);
  }
  catch (...)
  {
    queue.cancel();
    producer.join();
    throw;
  }
  producer.join();
  if (producer_error)
    std::rethrow_exception(producer_error);
  return energy_.finish();
}
}  // namespace scanhead
