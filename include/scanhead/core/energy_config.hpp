/// \file energy_config.hpp
/// \brief Parameters of the energy stage (SPEC §5).
#pragma once

namespace scanhead
{
struct EnergyConfig
{
  double spot_diameter_m = 70.0e-6;   ///< 1/e² diameter 2w of the Gaussian spot [m] (THESIS §2.5)
  double pixel_m = 5.0e-6;            ///< map pixel pitch [m]
  double max_substep_radii = 0.25;    ///< sub-step length along the path, in spot radii w
  double truncation_radii = 3.0;      ///< footprint drawn out to this many radii w
  double map_margin_m = 0.5e-3;       ///< map extends the job's bounding box by this [m]
  double corner_min_angle_deg = 1.0;  ///< direction changes above this are reported as corners

  void validate() const;
};
}  // namespace scanhead
