/// \file galvo_params.hpp
/// \brief The X and Y galvos of this project: plant parameters and cascade gains (SPEC §3).
///
/// The references give no R, L, Jeq, B, Kc, Ke, Tp, Tc, Kr, ξr, ωres (SPEC §3). Values here are
/// design choices for a 10-mm-aperture moving-magnet galvo, tied to the THESIS where it can be:
/// - Kc/Jeq = 1.2e5 rad/s²/A for Y (implied by the THESIS speed gain Kiω = 7.48e-4 A/(°/s) =
///   0.0429 A/(rad/s) at the 5000 rad/s speed crossover, SPEC §3): Kc = 0.024 N·m/A (catalogue
///   range 5e-3..3e-2), Jeq = 2.0e-7 kg·m² (rotor + a 10-mm-class Y mirror, range 1e-7..1e-6).
/// - |R + jωL| = 3.3 Ω at 1e4 rad/s (SPEC §3) with a 60° phase: that is what the THESIS current
///   gains Kii = 1.91, Tii = 7e-5 need to cross at 1e4 rad/s with a 65° margin
///   (1.91·|1 + 1/(j·0.7)| = 3.33 Ω; 180 − 55 − 60 = 65°): R = 3.3 cos 60° = 1.65 Ω,
///   L = 3.3 sin 60° / 1e4 = 286 µH.
/// - X: same motor (R, L, Kc), lighter mirror Jeq = 1.4e-7 kg·m² (NC Fig. 4: X more dynamic than Y).
/// - B = 2e-6 N·m·s/rad (mechanical time constant Jeq/B = 0.1 s for Y), design choice.
/// - Tc = 1.206e-5 N·m (0.50 mA × Kc) and Tp = 1.0e-6 N·m, the same on both axes (one motor, one bearing
///   design): Tc fitted to THESIS Tableau 3.1 (3-axis simulator, conventional controller), the shares of the
///   contour points within 10, 20 and 30 µm for recipes 1–3 on the whole square-job layers, residual
///   (ours − thesis)/3 points (scripts/fit_servo_friction.py, pattern search; README "Servo friction fitted to
///   Tableau 3.1"). The THESIS identified this friction law from KM0 ramps (§2.2.1, Fig. 2.18/2.19) but prints no
///   value. The share under 10 µm is a threshold figure: an axis at rest along a contour side keeps a static error
///   ∝ Tc until the speed integrator takes it up; the share falls by 3.3 points per +10 % of Tc (3.1 per +10 % of
///   Tiω, 0.15 per +10 % of B), the shares under 20 and 30 µm and the fill rates by < 0.1. Tp is not identified
///   by these figures (no change over ±20 %): it is kept small. Before the fit: Tc = 3e-5, Tp = 1e-5 (guesses).
/// - Flexible mode: ξr = 0.02 (lightly damped mirror torsion), ωres/2π = 5.5 kHz (Y, larger
///   mirror) and 7.5 kHz (X), Kr = 2 ξr Kc/Jeq so that at ωres the mode's |ω/i| equals the rigid
///   one's (a +6 dB resonance on the rigid line), design choices.
/// - Driver supply ±30 V.
/// Gains: synthesiseGains() (loop_analysis.hpp) at the default 100 kHz controller rate, from the
/// THESIS targets (Y: current 1e4 rad/s / 65°, speed 5000 rad/s / 65°, position 3000 rad/s / 75°,
/// the PD on its large-Tdθ branch as the THESIS; X: the same margins, crossovers × 1.3). For Y it
/// gives Kii 1.76, Tii 7.05e-5, Kiω 0.0417, Kθ 32.1, Tdθ 0.082: the THESIS's own 1.91, 7e-5,
/// 0.0429, 32, 0.1 (SPEC §3).
#pragma once

#include "scanhead/servo/cascade_gains.hpp"
#include "scanhead/servo/galvo_plant.hpp"

namespace scanhead
{
/// \brief Crossover targets for the X galvo relative to Y's (X lighter: faster loops).
constexpr double kGalvoXCrossoverScale = 1.3;

/// \brief The Y galvo (THESIS bench, heavier mirror): the GalvoPlantParams defaults.
inline GalvoPlantParams defaultPlantY()
{
  return GalvoPlantParams{};
}

/// \brief The X galvo: Y's motor with a lighter mirror and a stiffer flexible mode.
inline GalvoPlantParams defaultPlantX()
{
  GalvoPlantParams p;
  p.inertia_kgm2 = 1.4e-7;
  p.mode_gain = 6857.14;  // 2 ξr Kc / Jeq = 2·0.02·0.024/1.4e-7
  p.mode_frequency_hz = 7500.0;
  return p;
}

/// \brief Y gains (CascadeGains defaults), synthesised for defaultPlantY() at 100 kHz.
inline CascadeGains defaultGainsY()
{
  return CascadeGains{};
}

/// \brief X gains, synthesised for defaultPlantX() at 100 kHz with crossovers × 1.3.
inline CascadeGains defaultGainsX()
{
  CascadeGains g;
  g.kii = 2.57181;
  g.tii_s = 7.13544e-5;
  g.kiw = 0.0369111;
  g.tiw_s = 1.57715e-3;
  g.ktheta = 41.9441;
  g.tdtheta_s = 0.0621025;
  return g;
}
}  // namespace scanhead
