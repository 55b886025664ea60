/// \file energy_config.hpp
/// \brief Parameters of the energy stage (SPEC §5).
#pragma once

#include <cstddef>

namespace scanhead
{
struct EnergyConfig
{
  double spot_diameter_m = 70.0e-6;   ///< 1/e² diameter 2w of the Gaussian spot [m] (THESIS §2.5)
  double pixel_m = 5.0e-6;            ///< map pixel pitch [m]
  double max_substep_radii = 0.5;     ///< sub-step length along the path, in spot radii w (ripple 2·exp(-π²/(2·0.5²)) = 5e-9)
  double truncation_radii = 2.5;      ///< footprint drawn out to this many radii w (exp(-12.5) = 4e-6 of the energy beyond, renormalised)
  double map_margin_m = 0.5e-3;       ///< map extends the job's bounding box by this [m]
  double corner_min_angle_deg = 1.0;  ///< direction changes above this are reported as corners
  double laser_path_tolerance_m = 30.0e-6;  ///< laser on farther than this from its mark: early/late/off path (THESIS 30 µm class)
  double track_exclude_ends_m = 100.0e-6;   ///< track energy: the start and end of each track left out (~3 spot radii)
  std::size_t track_max_samples = 1000000;  ///< track energy kept for jobs with at most this many laser-on samples (+1 per burst; 64 B each)

  void validate() const;
};
}  // namespace scanhead
