/// \file steady_moving_spot.hpp
/// \brief Analytic reference for the thermal layer model: the steady rise under a Gaussian spot
/// moving at constant speed over an infinite bed of constant (melted-cell) properties, and its melt
/// pool (the moving point source of Rosenthal, with the layer's loss term, convolved with the spot).
#pragma once

#include "scanhead/thermal/thermal_config.hpp"

namespace scanhead
{
/// \brief Steady rise T(ξ, η) [K] of the layer with a melted cell's properties everywhere (κ, λ =
/// kappaMelted(), conductivityMelted(): κ_s, λ_s unless "consolidate"; no switch, infinite bed)
/// under the spot moving at constant \p speed_m_s along +ξ, at (ξ, η) from the spot centre.
///
/// The moving-frame equation κ v ∂T/∂ξ + λ ΔT − (λ_s/δ²) T = −q/h has for a point source Q the
/// solution \f$ T = \frac{Q}{2\pi\lambda h} e^{-v\xi/(2a)} K_0\!\left(\rho\sqrt{(v/2a)^2 + m^2}\right) \f$,
/// a = λ/κ, m² = λ_s/(λ δ²). Convolved with the Gaussian spot it is evaluated as the time integral
/// \f[ T(\xi,\eta) = \frac{A P}{h\kappa}\int_0^\infty \frac{e^{-t/\tau}}{2\pi\sigma^2(t)}
///     \exp\!\left(-\frac{(\xi + v t)^2 + \eta^2}{2\sigma^2(t)}\right) dt,\quad \sigma^2 = \frac{w^2}{4} + 2 a t,\;
///     \tau = \frac{\kappa\delta^2}{\lambda_s} \f]
/// (adaptive Simpson, absolute tolerance 1e-7·(melt rise), on pieces split geometrically from the
/// spot's diffusion time w²/(8a)/64 up to 60 τ and around the passage time −ξ/v).
/// \p speed_m_s may be 0 (dwell).
double steadyMovingSpotRise(const ThermalConfig& config, double power_w, double speed_m_s, double xi_m, double eta_m);

/// \brief Melt pool of steadyMovingSpotRise: the region above melt − ambient.
struct SteadyMeltPool
{
  double peak_k = 0.0;     ///< highest steady rise (on the axis) [K]
  double peak_xi_m = 0.0;  ///< where [m] (≤ 0: behind the spot centre)
  double front_m = 0.0;    ///< ξ of the front on the axis [m]
  double rear_m = 0.0;     ///< ξ of the rear [m]
  double length_m = 0.0;   ///< front − rear (0 if the peak is below melting) [m]
  double width_m = 0.0;    ///< widest extent across [m]
};
/// \brief Root finding (bisection to 1e-9 m) on steadyMovingSpotRise; width the maximum over ξ.
SteadyMeltPool steadyMeltPool(const ThermalConfig& config, double power_w, double speed_m_s);
}  // namespace scanhead
