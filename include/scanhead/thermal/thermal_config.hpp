/// \file thermal_config.hpp
/// \brief Parameters of the optional 2D thermal model of the layer (SPEC §5, last bullet; PATH §2.2–2.3).
///
/// Defaults: a 316L stainless-steel powder bed, 50 µm layer. Where PATH §2.3 gives a value it is
/// used (ρ, c_p, λ of powder and solid, δ, T0); the rest are documented choices:
///   - PATH gives no absorptivity (its source eq. 4 folds it into P) and its P = 7.68e9 W/m²,
///     C_g = 100 m⁻² describe a spot of a non-dimensional plate, not a 70 µm spot: not used.
///   - PATH's phase-change temperature T_ph = 500 °C is illustrative (its Fig. 3); 316L melts at
///     1375–1400 °C (solidus–liquidus, ASM Handbook vol. 1 / AK Steel 316L data sheet) and the
///     outputs here are melt-pool figures, so the default is the 316L liquidus, 1400 °C.
///   - PATH's eq. 5 is per unit volume but its source q is per unit area: q is divided by the
///     layer thickness h (the layer's temperature is its depth average).
#pragma once

#include <cstddef>
#include <string>

namespace scanhead
{
struct ThermalConfig
{
  // --- Material (PATH eq. 1: powder or solid per cell) ---
  double density_solid_kg_m3 = 8000.0;         ///< ρ_solide [kg/m³] (PATH §2.3; 316L 7990 at 20 °C)
  double density_powder_kg_m3 = 4000.0;        ///< ρ_poudre [kg/m³] (PATH §2.3: 50 % packing)
  double heat_capacity_solid_j_kg_k = 450.0;   ///< c_p,solide [J/(kg·K)] (PATH §2.3; 316L ≈ 500 at 20 °C)
  double heat_capacity_powder_j_kg_k = 450.0;  ///< c_p,poudre [J/(kg·K)] (PATH §2.3: same as solid)
  double conductivity_solid_w_m_k = 15.0;      ///< λ_solide [W/(m·K)] (PATH §2.3; 316L 16 at 100 °C)
  double conductivity_powder_w_m_k = 0.25;     ///< λ_poudre [W/(m·K)] (PATH §2.3: 1.7 % of solid, powder beds ~1 %)
  double loss_depth_m = 50.0e-6;               ///< δ, depth of the loss term λ_solide/δ²·T [m] (PATH §2.3: 5e-5)
  double layer_thickness_m =
      50.0e-6;  ///< h, thickness the absorbed power heats, q_vol = q/h [m] (30–50 µm layers; = δ)
  double melt_temperature_k = 1673.15;  ///< phase change powder → solid and melt-pool edge [K] (316L liquidus 1400 °C)
  double ambient_temperature_k = 303.15;  ///< bed temperature T0 [K] (PATH §2.3: 30 °C); T is the rise over it
  /// What a cell's switch powder → solid does (PATH says only that the properties switch):
  ///   - "keep_temperature": PATH read literally (κ ∂T/∂t): T continuous, κ_p → κ_s, λ_p → λ_s; the
  ///     energy h·(κ_s − κ_p)·T·dA this creates is booked as phase_switch_j (with PATH's values it
  ///     doubles the cell's energy, and depends on dt: cells overshoot T_melt within a step).
  ///   - "keep_energy": the conservative form ∂(κT)/∂t: κ_p → κ_s, λ_p → λ_s, T scaled by κ_p/κ_s.
  ///   - "consolidate": the powder densifies to solid, mass per area kept (layer thickness
  ///     h·ρ_p/ρ_s): per unit volume of the layer κ = ρ_p·c_s, λ = λ_s·ρ_p/ρ_s (PATH's values:
  ///     κ = κ_p = 1.8e6 J/(m³·K), λ = 7.5 W/(m·K)); T continuous (energy kept when c_s = c_p,
  ///     else booked as phase_switch_j).
  /// Default "consolidate": energy kept, T continuous, least sensitive to the grid (200 W, 1 m/s,
  /// cells 10 / 5 / 2.5 µm: pool length 447 / 450 / 453 µm); on the same track "keep_temperature"
  /// creates energy worth 54 % of the absorbed one (pool 625 µm), "keep_energy" gives 489 µm.
  std::string phase_switch = "consolidate";

  // --- Source (PATH eq. 3 with f = 2: q = 2·A·P/(π w²)·exp(−2 r²/w²)) ---
  double absorptivity = 0.35;  ///< A, absorbed share of P (316L powder, conduction mode: 0.3–0.4, Trapp et al. 2017)
  double spot_diameter_m = 70.0e-6;  ///< 1/e² diameter 2w [m] (THESIS §2.5, as energy.spot_diameter_m)
  double source_truncation_radii =
      3.0;  ///< footprint drawn out to this many w, square stencil (exp(−18) beyond), renormalised
  double max_substep_radii =
      0.5;  ///< a sample's energy is spread along its segment in sub-steps ≤ this many w (as energy.*)

  // --- Numerics ---
  double cell_m = 10.0e-6;            ///< cell pitch [m] (w = 3.5 cells)
  double window_m = 2.0e-3;           ///< side of the square window that follows the spot [m] (200 cells)
  double recentre_margin_m = 0.3e-3;  ///< the window re-centres on the spot when it comes this close to an edge [m]
  /// Thermal time step dt = step_samples·Ts (NC periods; the source of each sample is kept). 200 W,
  /// 1 m/s, default bed: steady pool length 447 / 450 / 471 µm for 1 / 2 / 5, throughput ×1 / ×1.7 / ×3.3.
  std::size_t step_samples = 2;
  /// Conductivity of a face between two cells: "arithmetic" (λ_a + λ_b)/2 or "harmonic" 2λ_aλ_b/(λ_a + λ_b).
  /// Equal cells give the same. At a powder–solid face (contrast 30–60) the harmonic mean puts half a
  /// powder cell's resistance between the pool and the powder it melts, so the melt front creeps by
  /// cells: 200 W, 1 m/s, default bed, cells 10 / 5 / 2.5 µm: harmonic L = 519 / 495 / 476 µm,
  /// W = 104 / 114 / 126 µm; arithmetic L = 447 / 450 / 453 µm, W = 130 / 140 / 142 µm.
  std::string face_conductivity = "arithmetic";
  double active_threshold_k = 1.0e-3;  ///< cells below this rise, outside the hot region's box, are set to 0 [K]

  // --- Statistics ---
  double settle_time_s = 1.0e-3;  ///< steps count in the steady means once the laser has been on this long [s]

  void validate() const;

  double meltRiseK() const { return melt_temperature_k - ambient_temperature_k; }         ///< phase-change rise [K]
  double kappaSolid() const { return density_solid_kg_m3 * heat_capacity_solid_j_kg_k; }  ///< κ_s = ρ c_p [J/(m³·K)]
  double kappaPowder() const { return density_powder_kg_m3 * heat_capacity_powder_j_kg_k; }  ///< κ_p [J/(m³·K)]
  /// \brief κ of a melted cell [J/(m³·K)] (κ_s, or ρ_p·c_s for "consolidate").
  double kappaMelted() const
  {
    return phase_switch == "consolidate" ? density_powder_kg_m3 * heat_capacity_solid_j_kg_k : kappaSolid();
  }
  /// \brief λ of a melted cell [W/(m·K)] (λ_s, or λ_s·ρ_p/ρ_s for "consolidate").
  double conductivityMelted() const
  {
    return phase_switch == "consolidate" ? conductivity_solid_w_m_k * density_powder_kg_m3 / density_solid_kg_m3
                                         : conductivity_solid_w_m_k;
  }
  double lossCoefficient() const
  {
    return conductivity_solid_w_m_k / (loss_depth_m * loss_depth_m);
  }  ///< λ_s/δ² [W/(m³·K)]
};
}  // namespace scanhead
