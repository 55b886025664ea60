/// \file cam_config.hpp
/// \brief The cam settings: how job files are read into a Job.
#pragma once

#include <array>
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
  /// Segment files, column 5: "auto" (a coefficient of mark_power_w if the column's header word starts with "pmod",
  /// the power in W if it starts with "power"; with neither, a coefficient if every row's value is <= 1, else W),
  /// "coefficient" or "watts" (job_files.hpp).
  std::string segment_power = "auto";
  /// Placement of the job (plate frame) on the field: p_field = R(rotation_deg)·p + offset_m, the rotation about the
  /// plate origin; with centre, the offset is taken from the bounding-box centre of the rotated job (the whole file
  /// for layered files, so that every layer shares one placement): p_field = R·(p − c) + offset_m (job_placement.hpp).
  std::array<double, 2> offset_m = {0.0, 0.0};
  double rotation_deg = 0.0;
  bool centre = false;

  void validate() const;
};
}  // namespace scanhead
