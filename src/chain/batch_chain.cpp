#include "scanhead/chain/batch_chain.hpp"

#include <exception>
#include <thread>

#include "scanhead/common/bounded_queue.hpp"

namespace scanhead
{
namespace
{
/// Spot chunks in flight between the two threads: enough to absorb the jitter of either side,
/// few enough that memory stays small (4 × 1000 samples × 88 B).
constexpr std::size_t kQueuedChunks = 4;
}  // namespace

BatchChain::BatchChain(const ChainConfig& config, const OpticalModel& optics)
  : config_(config)
  , nc_(config, optics)
  , servo_(config.servo)
  , optics_(optics)
  , energy_(config)
{
}

SpotChunk BatchChain::nextSpotChunk()
{
  const NcOutput nc = nc_.process(config_.stream.chunk_samples);
  const JointChunk joints = servo_.process(nc.setpoint);
  return optics_.process({nc.setpoint, joints, nc.laser});
}

RunMetrics BatchChain::run(const Job& job, const ProgressCallback& progress)
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
