/// \file cam_config.hpp
/// \brief The cam settings: how job files are read into a Job.
#pragma once

#include <string>

namespace scanhead
{
/// \brief How job files are read (CLI and segment files; YAML jobs carry everything themselves).
struct CamConfig
{
  int layer = 0;                ///< CLI layer to run, in file order; -1: all layers in order
  std::string units = "m";      ///< segment files: coordinates in "m" or "mm"
  double mark_speed_mps = 1.0;  ///< CLI marks without $$SPEED [m/s] (THESIS recipe 1 hatch speed)
  double jump_speed_mps = 4.5;  ///< jumps between CLI marks [m/s] (THESIS recipe 1)
  double mark_power_w = 200.0;  ///< CLI marks without $$POWER; segment files: power at coefficient 1 [W]
  std::string shape_file;       ///< polygon file (shape.hpp) the built-in fills use; "": square or circle

  void validate() const;
};
}  // namespace scanhead
