/// \file segment_integral.hpp
/// \brief The Gaussian spot swept at constant velocity along a straight segment, integrated in closed form (SPEC §5).
#pragma once

#include <Eigen/Core>

#include "scanhead/energy/spot_footprint.hpp"

namespace scanhead
{
/// \brief Energy density left by a spot of footprint Q (spot_footprint.hpp) that moves at constant velocity from c0
/// to c0 + D, spending the energy E_s uniformly in time.
///
/// With r = p − c0 and the spot at c0 + τD, τ ∈ [0, 1]:
/// \f[ E(p) = E_s\,\frac{\sqrt{\det Q}}{\pi}\int_0^1 e^{-(r - \tau D)^\top Q\,(r - \tau D)}\,d\tau . \f]
/// Completing the square in τ (the standard Gaussian integral \f$\int_{x_0}^{x_1} e^{-x^2}dx =
/// \frac{\sqrt\pi}{2}[\mathrm{erf}\,x_1 - \mathrm{erf}\,x_0]\f$, Abramowitz & Stegun 7.1.1): with
/// \f[ A = D^\top Q D, \qquad u(r) = \frac{D^\top Q\,r}{\sqrt A} = g^\top r, \qquad g = \frac{Q D}{\sqrt A}, \f]
/// the exponent is \f$ (\sqrt A\,\tau - u)^2 + r^\top Q r - u^2 \f$, and the remainder \f$ r^\top (Q - Q D D^\top
/// Q/A)\,r \f$ is of rank 1 (its matrix annihilates D): \f$ = (m^\top r)^2 \f$ with m = √κ·n̂, n̂ the unit normal
/// to D and \f$ \kappa = \hat n^\top Q \hat n - (\hat n^\top Q D)^2/A = \det Q\,|D|^2/A \f$ (Lagrange's identity in
/// 2-D). Hence
/// \f[ E(p) = E_s\,\frac{\sqrt{\det Q}}{\pi}\,\frac12\sqrt{\frac{\pi}{A}}\;e^{-(m^\top r)^2}
///     \left[\mathrm{erf}(\sqrt A - u) + \mathrm{erf}(u)\right] : \f]
/// a Gaussian across the segment (in the footprint's own metric: the oblique footprint is included) times an erf
/// difference along it. Both u and mᵀr are linear in p, so along a map row the cross factor follows a multiplicative
/// recurrence and the bracket is 2 (resp. 0) to double precision wherever |u| and |√A − u| exceed 6 (erfc 6 = 2e-17,
/// below half an ulp of 1). For a segment swept at velocity v for a time T, D = vT and √A = √(vᵀQv)·T.
///
/// Limit A → 0 (a stationary dwell): erf(√A − u) + erf(u) → (2/√π)·√A·e^{−u²}, so E → E_s(√det Q/π)·e^{−rᵀQr}. Below
/// √A = kStationaryLimit the erf difference would lose digits to cancellation (1e-16/√A), so such a segment is
/// evaluated as a dwell at its midpoint: the error of that is O(A/12) relative, 8e-10 at the limit.
struct SegmentIntegral
{
  static constexpr double kStationaryLimit = 1.0e-4;  ///< √A below this: a dwell at the midpoint

  /// \brief The closed form for footprint \p fp swept along the displacement \p d [m].
  SegmentIntegral(const SpotFootprint& fp, const Eigen::Vector2d& d);

  bool stationary = false;                      ///< √A < kStationaryLimit: W(r) = exp(−(r − D/2)ᵀQ(r − D/2))
  double sqrt_a = 0.0;                          ///< √A = √(DᵀQD) [-]
  Eigen::Vector2d g = Eigen::Vector2d::Zero();  ///< u = gᵀr [1/m]
  Eigen::Vector2d m = Eigen::Vector2d::Zero();  ///< cross factor exp(−(mᵀr)²) [1/m]
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();  ///< stationary: D/2, where r is measured from [m]
  double qxx = 0.0, qxy = 0.0, qyy = 0.0;            ///< Q [1/m²]
  double amplitude = 0.0;  ///< E(p) = E_s·amplitude·W(r): √det Q/π·½√(π/A), or √det Q/π stationary [1/m²]

  /// \brief W(r) = exp(−(mᵀr)²)·[erf(√A − u) + erf(u)] (or the dwell's exp(−rᵀQr)), r = p − c0 [m]; with std::erf:
  /// the reference of the row-by-row evaluation in stroke_deposit.cpp.
  double weight(const Eigen::Vector2d& r) const;
  /// \brief E(p) [J/m²] for energy \p energy_j (untruncated, unnormalised: the closed form itself).
  double density(const Eigen::Vector2d& r, double energy_j) const { return energy_j * amplitude * weight(r); }
};
}  // namespace scanhead
