/// \file transfer_forms.hpp
/// \brief The two transfer functions of a galvo's base model, fitted by the identification, their
/// parameters (G1, τ1, G2, τ2, τ3), the way back to the physical parameters (THESIS eq. 2.13), and
/// the true plant's responses they are checked against (SPEC §3; THESIS §2.2.1.2 and app. A).
///
/// The two transfer functions of the base model (rigid rotor, no friction offsets, no mode):
/// \f[ \frac{\theta}{i}(s) = \frac{K_c/B}{s\,(1 + \frac{J_{eq}}{B}s)} = \frac{G_1}{s(1 + \tau_1 s)}, \f]
/// \f[ \frac{i}{U}(s) = \frac{J_{eq}s + B}{(R + Ls)(J_{eq}s + B) + K_eK_c}
///     = \frac{G_2(1 + \tau_1 s)}{(1 + \tau_2 s)(1 + \tau_3 s)}, \f]
/// whence \f$G_1 = K_c/B\f$, \f$\tau_1 = J_{eq}/B\f$, \f$G_2 = B/(BR + K_eK_c)\f$,
/// \f$\tau_2\tau_3 = G_2 L\tau_1\f$, \f$\tau_2 + \tau_3 = G_2(L + R\tau_1)\f$.
#pragma once

#include <complex>

#include "scanhead/servo/galvo_plant.hpp"

namespace scanhead
{
/// \brief The parameter set (G1, τ1, G2, τ2, τ3) of the two fitted forms (THESIS eq. 2.10, 2.11).
///
/// The i/U denominator is kept as \f$(1 + \tau_2 s)(1 + \tau_3 s) = 1 + \sigma s + \pi s^2\f$,
/// σ = τ2 + τ3, π = τ2τ3: with a small viscous friction B and a large Kc²/R the two poles are a
/// complex pair (τ2, τ3 complex conjugates; the default Y galvo has ζ ≈ 0.9), which the real
/// (σ, π) describe continuously. tau2()/tau3() give the roots, complex if so.
struct TransferForms
{
  double g1_rad_per_as = 0.0;   ///< G1 = Kc/B [rad/(A·s)]
  double tau1_s = 0.0;          ///< τ1 = Jeq/B [s]
  double g2_a_per_v = 0.0;      ///< G2 = B/(BR + KeKc) [A/V]
  double tau_sum_s = 0.0;       ///< σ = τ2 + τ3 = G2(L + Rτ1) [s]
  double tau_product_s2 = 0.0;  ///< π = τ2τ3 = G2Lτ1 [s²]

  /// \brief τ2, the root of τ² − στ + π = 0 with the larger real part (then the larger
  /// imaginary part) [s]; τ3 = its partner.
  std::complex<double> tau2() const;
  std::complex<double> tau3() const;
};

/// \brief The five physical parameters the identification recovers.
struct PhysicalParams
{
  double resistance_ohm = 0.0;            ///< R [Ω]
  double inductance_h = 0.0;              ///< L [H]
  double torque_constant_nm_per_a = 0.0;  ///< Kc = Ke [N·m/A]
  double viscous_nms = 0.0;               ///< B [N·m·s/rad]
  double inertia_kgm2 = 0.0;              ///< Jeq [kg·m²]
};

/// \brief (G1, τ1, G2, σ, π) of a plant's base model, from the relations in the file comment.
/// Friction offsets and the flexible mode are not part of the base model and are ignored.
TransferForms transferFormsOf(const GalvoPlantParams& plant);

/// \brief THESIS eq. (2.13) (SPEC §3): with \f$r_1 = 1/\tau_2,\ r_2 = 1/\tau_3,\ a = \tau_1\f$,
/// \f[ c = \frac{1}{G_2 a r_1 r_2},\quad b = \frac{a c (r_1 + r_2) - c}{a},\quad
///     d = \frac{(ba + c)^2 - 4acb - (ac)^2(r_1 - r_2)^2}{4ac}, \f]
/// \f[ L = c,\ R = b,\ K_c = K_e = d/G_1,\ B = K_c/G_1,\ J_{eq} = aB. \f]
/// Evaluated as written in complex arithmetic (r1, r2 conjugates for a complex pole pair: every
/// quantity above is then real, r1 + r2 = σ/π, r1r2 = 1/π, (r1 − r2)² = (σ² − 4π)/π²).
/// Checked against the plant equations: c = L from τ2τ3 = G2Lτ1; b = R from τ2 + τ3 = G2(L + Rτ1);
/// d simplifies to \f$ac\,r_1r_2 - b = 1/G_2 - R = K_eK_c/B\f$. So (2.13) is right; the thesis'
/// printed eq. (2.9) and (2.12) drop a factor R (i/U lacks 1/R, "1 + KeKc/B" should read
/// "R + KeKc/B", "Jeq/B·L/R" should read "Jeq/B·L", "Jeq/B + L/R" should read "L + R·Jeq/B").
/// \throws NumericalError if a parameter comes out non-positive or non-finite
PhysicalParams recoverPhysicalParams(const TransferForms& forms);

/// \brief \f$G_1/(s(1 + \tau_1 s))\f$ at \f$s = j2\pi f\f$ [rad/A].
std::complex<double> thetaPerCurrent(const TransferForms& forms, double f_hz);
/// \brief \f$G_2(1 + \tau_1 s)/(1 + \sigma s + \pi s^2)\f$ at \f$s = j2\pi f\f$ [A/V].
std::complex<double> currentPerVoltage(const TransferForms& forms, double f_hz);

/// \brief The exact zero-order-hold equivalent of currentPerVoltage() at \f$z = e^{j2\pi fT}\f$
/// [A/V] (the driver holds U over each period T):
/// \f[ G(z) = (1 - z^{-1})\,\mathcal{Z}\Big\{\frac{G(s)}{s}\Big\}
///     = r_0 + (1 - z^{-1})\sum_{j=2,3}\frac{r_j}{1 - e^{p_jT}z^{-1}}, \f]
/// with the partial fractions of G(s)/s: \f$r_0 = G_2\f$ at s = 0 and, at the poles
/// \f$p_j = -1/\tau_j\f$ (distinct, possibly a complex pair),
/// \f$r_j = G_2(1 + \tau_1 p_j)/(p_j\,\pi\,(p_j - p_{other}))\f$. Coincident poles are split by a
/// relative 1e-6 (the limit of the partial fractions).
/// (The hold equivalent as in G. F. Franklin, J. D. Powell, M. L. Workman, "Digital Control of
/// Dynamic Systems", 3rd ed., 1998, the chapter on discrete equivalents.)
std::complex<double> currentPerVoltageZoh(const TransferForms& forms, double f_hz, double period_s);

/// \brief True plant frequency responses (continuous, including the flexible mode):
/// \f$\theta/i = K_c/(s(J_{eq}s + B)) + K_r/(s^2 + 2\xi_r\omega_{res}s + \omega_{res}^2)\f$.
std::complex<double> trueThetaPerCurrent(const GalvoPlantParams& plant, double f_hz);
/// \brief \f$i/U = 1/(R + Ls + K_e\,\omega/i)\f$ with ω/i as in galvo_plant.hpp (back-EMF from the
/// mirror speed, THESIS eq. 2.30, so the flexible mode shows in i/U too).
std::complex<double> trueCurrentPerVoltage(const GalvoPlantParams& plant, double f_hz);
}  // namespace scanhead
