/// \file thermal_config.cpp
#include "scanhead/thermal/thermal_config.hpp"

#include <cmath>

#include "scanhead/common/config_check.hpp"
#include "scanhead/common/errors.hpp"

namespace scanhead
{
namespace
{
constexpr double kMaxWindowCells = 4096.0;  // per side: 16.7 M cells, ~0.5 GB of fields
}  // namespace

void ThermalConfig::validate() const
{
  requireSetting(density_solid_kg_m3 > 0.0, "thermal.density_solid_kg_m3", "> 0", density_solid_kg_m3);
  requireSetting(density_powder_kg_m3 > 0.0, "thermal.density_powder_kg_m3", "> 0", density_powder_kg_m3);
  requireSetting(heat_capacity_solid_j_kg_k > 0.0, "thermal.heat_capacity_solid_j_kg_k", "> 0",
                 heat_capacity_solid_j_kg_k);
  requireSetting(heat_capacity_powder_j_kg_k > 0.0, "thermal.heat_capacity_powder_j_kg_k", "> 0",
                 heat_capacity_powder_j_kg_k);
  requireSetting(conductivity_solid_w_m_k > 0.0, "thermal.conductivity_solid_w_m_k", "> 0", conductivity_solid_w_m_k);
  requireSetting(conductivity_powder_w_m_k > 0.0, "thermal.conductivity_powder_w_m_k", "> 0",
                 conductivity_powder_w_m_k);
  requireSetting(loss_depth_m > 0.0, "thermal.loss_depth_m", "> 0", loss_depth_m);
  requireSetting(layer_thickness_m > 0.0, "thermal.layer_thickness_m", "> 0", layer_thickness_m);
  requireSetting(ambient_temperature_k > 0.0, "thermal.ambient_temperature_k", "> 0", ambient_temperature_k);
  requireSetting(melt_temperature_k > ambient_temperature_k, "thermal.melt_temperature_k",
                 "> thermal.ambient_temperature_k", melt_temperature_k);
  requireChoice(phase_switch, "thermal.phase_switch", {"keep_temperature", "keep_energy", "consolidate"});
  requireSetting(absorptivity > 0.0 && absorptivity <= 1.0, "thermal.absorptivity", "in (0, 1]", absorptivity);
  requireSetting(spot_diameter_m > 0.0, "thermal.spot_diameter_m", "> 0", spot_diameter_m);
  requireSetting(source_truncation_radii >= 2.0, "thermal.source_truncation_radii", ">= 2", source_truncation_radii);
  requireSetting(max_substep_radii > 0.0, "thermal.max_substep_radii", "> 0", max_substep_radii);
  requireSetting(cell_m > 0.0, "thermal.cell_m", "> 0", cell_m);
  // At least one cell per radius, or the sampled Gaussian is a single cell.
  requireSetting(cell_m <= 0.5 * spot_diameter_m, "thermal.cell_m", "<= spot_diameter_m/2", cell_m);
  requireSetting(recentre_margin_m >= source_truncation_radii * 0.5 * spot_diameter_m, "thermal.recentre_margin_m",
                 ">= source_truncation_radii·spot_diameter_m/2 (the footprint stays in the window)", recentre_margin_m);
  requireSetting(window_m > 2.0 * recentre_margin_m + 2.0 * cell_m, "thermal.window_m",
                 "> 2·recentre_margin_m + 2·cell_m", window_m);
  requireSetting(window_m / cell_m <= kMaxWindowCells, "thermal.window_m", "<= 4096·cell_m", window_m);
  requireChoice(face_conductivity, "thermal.face_conductivity", {"arithmetic", "harmonic"});
  if (step_samples < 1 || step_samples > 1000000)
    failSetting("thermal.step_samples", "in [1, 1000000]", static_cast<double>(step_samples));
  requireSetting(active_threshold_k > 0.0 && active_threshold_k < meltRiseK(), "thermal.active_threshold_k",
                 "in (0, melt_temperature_k − ambient_temperature_k)", active_threshold_k);
  requireSetting(settle_time_s >= 0.0, "thermal.settle_time_s", ">= 0", settle_time_s);
}
}  // namespace scanhead
