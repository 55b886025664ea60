/// \file energy_config.hpp
/// \brief Parameters of the energy stage (SPEC §5).
#pragma once

#include <cstddef>
#include <string>

namespace scanhead
{
struct EnergyConfig
{
  /// Map pixel against the spot diameter d: at most d/2 (= w, a pixel wider than the 1/e² radius
  /// cannot resolve the spot; questionable above d/5, run_plan.hpp), at least d/100.
  static constexpr double kMaxPixelPerDiameter = 0.5;
  static constexpr double kMinPixelPerDiameter = 0.01;
  /// Largest footprint truncation [radii w]: exp(-2·5²) = 2e-22 of the peak (float rounds at 2.9 w).
  static constexpr double kMaxTruncationRadii = 5.0;

  double spot_diameter_m = 70.0e-6;  ///< 1/e² diameter 2w of the Gaussian spot [m] (THESIS §2.5)
  double pixel_m = 5.0e-6;           ///< map pixel pitch [m]
  /// How each sample's energy reaches the map: "trapezoid" (the time integral along the path by the trapezoid rule
  /// at the samples with the kinks' Euler–Maclaurin shift: node_chain.hpp, node_deposit.hpp), "exact" (the footprint
  /// integrated in closed form along the segment to the next sample, consecutive samples of one straight
  /// constant-velocity stroke merged: segment_integral.hpp, stroke_merger.hpp) or "sampled" (point-sampled at
  /// sub-steps of max_substep_radii: sampled_deposit.hpp).
  std::string method = "trapezoid";
  double stroke_tolerance_m = 1.0e-8;  ///< exact: samples within this of the ideal constant-velocity stroke merge
                                       ///< (error ≤ 1.77·tol/w of the peak)
  double max_substep_radii =
      0.5;  ///< sampled: sub-step length along the path, in spot radii w (ripple 2·exp(-π²/(2·0.5²)) = 5e-9)
  double truncation_radii =
      2.5;  ///< footprint drawn out to this many radii w (exp(-12.5) = 4e-6 of the energy beyond, renormalised)
  double map_margin_m = 0.5e-3;       ///< map extends the job's bounding box by this [m]
  double corner_min_angle_deg = 1.0;  ///< direction changes above this are reported as corners
  double laser_path_tolerance_m =
      30.0e-6;  ///< laser on farther than this from its mark: early/late/off path (THESIS 30 µm class)
  double track_exclude_ends_m = 100.0e-6;  ///< track energy: the start and end of each track left out (~3 spot radii)
  std::size_t track_max_samples =
      1000000;  ///< track energy sampled on at most this many laser-on samples (longer jobs: every k-th, k doubling)
  std::size_t tile_cache_bytes =
      268435456;                  ///< energy-map tiles kept in memory; the rest spill to a temporary file [bytes]
  std::string spill_dir;          ///< folder of that file (removed at once, freed at exit); "": $TMPDIR, else /tmp
  bool oblique_incidence = true;  ///< stretch the footprint by 1/cos(incidence) along the beam's plane of incidence
  /// Distance to focus: "none" (in focus everywhere, a dynamic-focus head), "fixed" (defocus_m everywhere),
  /// "field" (a static focus on the sphere of radius focus_distance_m: z = L·(1/cos θ − 1) + defocus_m).
  std::string defocus_mode = "none";
  double defocus_m = 0.0;         ///< distance of the plane beyond the waist [m] (modes fixed, field)
  double focus_distance_m = 0.7;  ///< last mirror to the plane at the field centre [m] (our URDF: 0.7 m)
  double wavelength_m = 1.07e-6;  ///< laser wavelength [m] (Yb fibre laser, usual in LPBF)
  double beam_quality_m2 = 1.1;   ///< M² of the beam (single-mode fibre laser: 1.05–1.2)
  std::size_t crop_parts = 1;     ///< full-resolution crops of the job's first parts (THESIS job: squares)
  std::string crop_regions;       ///< more crops: "x0,y0,x1,y1[,name];…" [m]
  std::size_t contour_max_samples =
      60000000;  ///< nearest-path contour error for jobs up to this many samples (16 B each)
  double contour_lag_s =
      -1.0;  ///< same-instant contour error: actual behind command by this [s]; < 0: filter + servo delay
  double same_instant_window_s =
      200.0e-6;  ///< same-instant contour error: search ± this around the lagged sample [s] (0: strict)

  void validate() const;
  /// \brief Rayleigh length z_R = π w0² / (M² λ) [m] of the waist w0 = spot_diameter_m / 2.
  double rayleighLength() const;
};
}  // namespace scanhead
