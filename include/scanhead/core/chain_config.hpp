/// \file chain_config.hpp
/// \brief The configuration of a whole run: one section per stage, plus the stream settings.
#pragma once

#include <cstddef>

#include "scanhead/core/energy_config.hpp"
#include "scanhead/core/nc_config.hpp"
#include "scanhead/core/optics_config.hpp"
#include "scanhead/core/servo_config.hpp"

namespace scanhead
{
struct StreamConfig
{
  std::size_t chunk_samples = 1000;  ///< samples per chunk of every full-rate stream (10 ms at 100 kHz)
  std::size_t window_chunks = 16;    ///< chunks the NC may run ahead of the last consumer (graph flow control)

  void validate() const;
};

struct ChainConfig
{
  StreamConfig stream;
  NcConfig nc;
  ServoConfig servo;
  OpticsConfig optics;
  EnergyConfig energy;

  /// \brief Validates every section. \throws ConfigError naming the first bad field
  void validate() const;
};
}  // namespace scanhead
