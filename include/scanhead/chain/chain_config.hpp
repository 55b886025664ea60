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

/// \brief Bounds on one batch run, checked by the run plan (run_plan.hpp) before anything that grows
/// with the job is allocated: beyond any of them the run is refused with a message naming the
/// cause and the key to raise.
struct LimitsConfig
{
  /// Machine time of the job (samples · Ts, tail included) [s]. 4 h: a whole LPBF layer takes
  /// minutes (the THESIS layer 305 s); at the measured 3–7× real time 4 h still needs ~1 h of wall.
  double max_machine_time_s = 14400.0;
  /// Samples of the job (every stage's work and the per-sample metrics grow with it): 4 h at 100 kHz.
  double max_samples = 1.44e9;
  /// Share of the machine's physical memory (/proc/meminfo MemTotal) the run's estimated peak may take.
  double max_memory_fraction = 0.5;
  /// Absolute bound on the estimated peak memory [bytes]; 0: the fraction above only.
  double max_memory_bytes = 0.0;

  /// \throws ConfigError naming limits.<field>
  void validate() const;
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
  LimitsConfig limits;

  /// \brief Validates every section. \throws ConfigError naming the first bad field
  void validate() const;
};
}  // namespace scanhead
