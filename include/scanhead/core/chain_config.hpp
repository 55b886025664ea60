/// \file chain_config.hpp
/// \brief The configuration of a whole run: one section per stage, plus the stream settings.
#pragma once

#include <cstddef>
#include <string>

#include "scanhead/core/energy_config.hpp"
#include "scanhead/core/nc_config.hpp"
#include "scanhead/core/optics_config.hpp"
#include "scanhead/core/recipe.hpp"
#include "scanhead/core/servo_config.hpp"

namespace scanhead
{
struct StreamConfig
{
  std::size_t chunk_samples = 1000;  ///< samples per chunk of every full-rate stream (10 ms at 100 kHz)
  std::size_t window_chunks = 16;    ///< chunks the NC may run ahead of the last consumer (graph flow control)

  void validate() const;
};

/// \brief How job files are read (CLI and segment files; YAML jobs carry everything themselves).
struct CamConfig
{
  int layer = 0;                    ///< CLI layer to run, in file order; -1: all layers in order
  std::string units = "m";          ///< segment files: coordinates in "m" or "mm"
  double mark_speed_mps = 1.0;      ///< CLI marks without $$SPEED [m/s] (THESIS recipe 1 hatch speed)
  double jump_speed_mps = 4.5;      ///< jumps between CLI marks [m/s] (THESIS recipe 1)
  double mark_power_w = 200.0;      ///< CLI marks without $$POWER; segment files: power at coefficient 1 [W]
  std::string shape_file;           ///< polygon file (shape.hpp) the built-in fills use; "": square or circle

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

  /// \brief Validates every section. \throws ConfigError naming the first bad field
  void validate() const;
};
}  // namespace scanhead
