/// \file chain_config.hpp
/// \brief The configuration of a whole run: one section per stage, plus the stream settings.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "scanhead/energy/energy_config.hpp"
#include "scanhead/job/cam_config.hpp"
#include "scanhead/job/recipe.hpp"
#include "scanhead/nc/nc_config.hpp"
#include "scanhead/optics/optics_config.hpp"
#include "scanhead/servo/servo_config.hpp"
#include "scanhead/thermal/thermal_config.hpp"

namespace scanhead
{
struct StreamConfig
{
  std::size_t chunk_samples = 1000;  ///< samples per chunk of every full-rate stream (10 ms at 100 kHz)
  std::size_t window_chunks = 16;    ///< chunks the NC may run ahead of the last consumer (graph flow control)
  /// Threads of the batch chain and the energy stage: 1 (all on the caller's), 2 (NC → servo → optics
  /// pipelined with the energy stage, whose trackers run beside the map). Results are bit-identical.
  std::size_t threads = 2;

  void validate() const;
};

/// \brief The optional thermal view of the energy stage (SPEC §5, PATH): off by default, and run on
/// a time window of the job, since it is slow (~3e4 samples/s: a whole layer would take hours).
struct ThermalStageConfig
{
  bool enabled = false;      ///< run the thermal model on the spot stream
  double start_s = 0.0;      ///< machine time it starts at [s]
  double duration_s = 0.05;  ///< how long it runs [s]; <= 0: to the end of the job
  ThermalConfig model;       ///< the model (keys thermal.<field>)
  void validate() const;
  /// \brief Whether sample \p index at period \p period_s lies in the window.
  bool covers(std::uint64_t index, double period_s) const
  {
    const double t = static_cast<double>(index) * period_s;
    return enabled && t >= start_s && (duration_s <= 0.0 || t < start_s + duration_s);
  }
};

struct ChainConfig
{
  CamConfig cam;
  StreamConfig stream;
  NcConfig nc;
  RecipeConfig recipe;
  ServoConfig servo;
  OpticsConfig optics;
  EnergyConfig energy;
  ThermalStageConfig thermal;

  /// \brief Validates every section. \throws ConfigError naming the first bad field
  void validate() const;
};
}  // namespace scanhead
