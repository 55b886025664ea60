/// \file batch_chain.hpp
/// \brief The whole chain in one process: NC → servo → optics → energy, chunk by chunk.
#pragma once

#include <functional>
#include <memory>

#include "scanhead/chain/chain_config.hpp"
#include "scanhead/chain/energy_stage.hpp"
#include "scanhead/servo/galvo_servo.hpp"
#include "scanhead/nc/nc_interpolator.hpp"
#include "scanhead/optics/optical_chain_stage.hpp"
#include "scanhead/common/package_path.hpp"
#include "scanhead/optics/optical_model.hpp"
#include "scanhead/optics/optics_loading.hpp"

namespace scanhead
{
/// \brief Called after each chunk with the samples done and the job's total.
using ProgressCallback = std::function<void(std::uint64_t done, std::uint64_t total)>;

class BatchChain
{
public:
  /// \param[in] optics must outlive this object
  BatchChain(const ChainConfig& config, const OpticalModel& optics);

  /// \brief Runs a validated job to the end. The energy stage stays available for the map and traces.
  RunMetrics run(const Job& job, const ProgressCallback& progress = {});

  const EnergyStage& energy() const { return *energy_; }
  const NcInterpolator& nc() const { return nc_; }
  std::uint64_t totalSamples() const { return nc_.totalSamples(); }

private:
  ChainConfig config_;
  const OpticalModel& optics_;
  NcInterpolator nc_;
  GalvoServo servo_;
  OpticalChainStage optical_stage_;
  std::unique_ptr<EnergyStage> energy_;
};
}  // namespace scanhead
