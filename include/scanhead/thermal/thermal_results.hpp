/// \file thermal_results.hpp
/// \brief The thermal view's results as plain structs: per-step melt pool (ThermalStep), its
/// statistics (MeltPoolStats), the energy books (ThermalEnergy), the window's fields (ThermalWindow)
/// and the melted cells (MeltedRaster). No model here: the producer is ThermalLayer (thermal_layer.hpp).
#pragma once

#include <cstdint>
#include <vector>

namespace scanhead
{
/// \brief One thermal time step (step_samples NC periods, fewer for the last one at finish()).
struct ThermalStep
{
  std::uint64_t first_index = 0;     ///< global index of the step's first sample
  std::uint32_t samples = 0;         ///< NC samples in the step
  double time_s = 0.0;               ///< end of the step, (first_index + samples)·Ts [s]
  double peak_k = 0.0;               ///< highest rise in the window at the end of the step [K]
  double length_m = 0.0;             ///< melt-pool extent along the scan direction (0 below melting) [m]
  double width_m = 0.0;              ///< melt-pool extent across it [m]
  bool laser_on = false;             ///< some sample of the step had power
  bool steady = false;               ///< counted in the steady means (laser on all the step, past settle_time_s)
  bool pool_at_window_edge = false;  ///< the melt pool reached the window edge: length/width truncated
};

/// \brief Mean and spread of the steady steps, maxima over all steps.
struct MeltPoolStats
{
  std::uint64_t steps = 0;  ///< thermal steps run
  std::uint64_t laser_on_steps = 0;
  std::uint64_t melting_steps = 0;  ///< steps whose peak was above melting
  std::uint64_t steady_steps = 0;   ///< steps in the means below
  double steady_length_mean_m = 0.0, steady_length_std_m = 0.0;
  double steady_width_mean_m = 0.0, steady_width_std_m = 0.0;
  double steady_peak_mean_k = 0.0, steady_peak_std_k = 0.0;
  double max_length_m = 0.0, max_width_m = 0.0, max_peak_k = 0.0;  ///< over all steps
};

/// \brief Energy books [J], cumulative since construction / reset().
///
/// absorbed + phase_switch = outside + stored + lost + left_window + truncated, to rounding (residual()).
struct ThermalEnergy
{
  double absorbed_j = 0.0;      ///< Σ A·P·Ts of all samples
  double outside_j = 0.0;       ///< the part of it whose footprint fell outside the window
  double stored_j = 0.0;        ///< now in the window, ∫ h·κ·T dA
  double lost_j = 0.0;          ///< through the loss term ∫∫ h·(λ_s/δ²)·T dA dt
  double phase_switch_j = 0.0;  ///< added by powder → solid switches at constant T, Σ h·(κ_melted − κ_p)·T·dA
  double left_window_j = 0.0;   ///< carried out of the window by its re-centring
  double truncated_j = 0.0;     ///< dropped with cells below active_threshold_k outside the hot box
  double residual_j() const
  {
    return absorbed_j + phase_switch_j - outside_j - stored_j - lost_j - left_window_j - truncated_j;
  }
};

/// \brief The window's fields as plain arrays, row-major (row j = y, row 0 at the lowest y).
///
/// Cells are those of the global grid of pitch cell_m anchored at the plane origin: cell (i, j) of the
/// window is global cell (origin_i + i, origin_j + j), covering [(origin_i + i)·cell_m, +cell_m) in x.
struct ThermalWindow
{
  double cell_m = 0.0;
  std::int64_t origin_i = 0, origin_j = 0;
  int width = 0, height = 0;
  std::vector<double> rise_k;       ///< temperature rise over the bed T [K]
  std::vector<std::uint8_t> solid;  ///< 1 once melted (solid properties), 0 powder
};

/// \brief The cells ever melted (global record) as a raster over their bounding box (same grid as ThermalWindow).
struct MeltedRaster
{
  double cell_m = 0.0;
  std::int64_t origin_i = 0, origin_j = 0;
  int width = 0, height = 0;
  std::vector<std::uint8_t> melted;  ///< row-major, 1 = melted
  std::uint64_t count = 0;           ///< melted cells
};
}  // namespace scanhead
