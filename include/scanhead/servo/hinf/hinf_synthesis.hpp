/// \file hinf_synthesis.hpp
/// \brief The THESIS's H∞ position controller of one galvo axis (chapter 3, §3.2.2–3.2.3): weights, standard form,
/// γ-iteration with the Glover–Doyle central controller, and the thesis's reduction (integrator, one state less).
#pragma once

#include <Eigen/Core>

#include "scanhead/servo/cascade_gains.hpp"
#include "scanhead/servo/galvo_plant.hpp"
#include "scanhead/servo/hinf/hinf_config.hpp"
#include "scanhead/servo/hinf/state_space.hpp"

namespace scanhead
{
/// \brief The synthesis model G(s) = θ/i_ref of THESIS eq. 3.27 (Fig. 3.4): the galvo of galvo_plant.hpp (friction
/// left out, flexible mode in) under its continuous current PI K_ii(1 + 1/(T_ii s)), output in DEGREES as the THESIS
/// works (the weights' gains are in °, A). Six states (i, ∫e_i, ω_r, θ, q̃, p) in the physical form of GalvoPlant,
/// not the companion form of eq. 3.39 (same transfer, better conditioned). Its RES(s) has the s in the numerator
/// of eq. 3.28 (eq. 3.31's coefficients drop it; the plant simulated here has it).
StateSpace synthesisModel(const GalvoPlantParams& plant, const CascadeGains& gains);

/// \brief The standard form P of THESIS eq. 3.26, inputs (r, d, u), outputs (e1, e2, ε):
/// e1 = W1(r − y), e2 = W2 u, ε = r − y, y = G(u + W3 d); states (G, W1, W2, W3).
StateSpace standardForm(const StateSpace& g, const HinfConfig& config);

/// \brief The problem centralController() solves for one axis: standardForm() of its synthesisModel(), states
/// balanced (balanceStates) and the exogenous inputs reordered (d, r, u), the one without a path to the measurement
/// first, so that D21 = [0 1].
StateSpace synthesisProblem(const GalvoPlantParams& plant, const CascadeGains& gains, const HinfConfig& config);

/// \brief The central controller of the standard H∞ problem at level γ, or false if γ is not achievable.
///
/// Glover–Doyle formulas for the general case (Zhou, Doyle & Glover 1996, Theorem 17.1; Glover & Doyle 1988):
/// with D12 = [0; I], D21 = [0 I], D22 = 0 (reached here by scaling u and y, which must be scalars) and
/// D1• = [D11 D12], D•1 = [D11; D21], R = D1•ᵀD1• − diag(γ²I, 0), R̃ = D•1D•1ᵀ − diag(γ²I, 0),
/// \f[ H_\infty = \begin{pmatrix} A & 0 \\ -C_1^TC_1 & -A^T \end{pmatrix} - \begin{pmatrix} B \\ -C_1^TD_{1\bullet}
/// \end{pmatrix}R^{-1}\begin{pmatrix} D_{1\bullet}^TC_1 & B^T \end{pmatrix},\quad
/// J_\infty = \begin{pmatrix} A^T & 0 \\ -B_1B_1^T & -A \end{pmatrix} - \begin{pmatrix} C^T \\ -B_1D_{\bullet1}^T
/// \end{pmatrix}\tilde R^{-1}\begin{pmatrix} D_{\bullet1}B_1^T & C \end{pmatrix}, \f]
/// γ is achievable iff γ > max(σ̄[D1111 D1112], σ̄[D1111ᵀ D1121ᵀ]), X∞ = Ric(H∞) ≥ 0, Y∞ = Ric(J∞) ≥ 0 and
/// ρ(X∞Y∞) < γ²; then with F = −R⁻¹(D1•ᵀC1 + BᵀX∞), L = −(B1D•1ᵀ + Y∞Cᵀ)R̃⁻¹, Z∞ = (I − γ⁻²Y∞X∞)⁻¹ the central
/// controller is (Â, B̂1, Ĉ1, D̂11) of the theorem.
/// \param[in] p  standard form with inputs (w, u) and outputs (z, y), \p nu controls and \p ny measurements last
bool centralController(const StateSpace& p, int ny, int nu, double gamma, StateSpace& controller);

/// \brief What the synthesis of one axis gives.
struct HinfDesign
{
  double gamma = 0.0;        ///< the γ of the central controller (feasible, within gamma_tolerance of optimal)
  double gamma_lower = 0.0;  ///< the largest γ found infeasible
  StateSpace full;           ///< the central controller, ε [°] → i_ref [A] (order of P: 9)
  /// The implemented controller K_r(s) = k_i/s + K_s(s): the smallest pole of the central one moved to the origin
  /// (K·(s − λ)/s, THESIS step 4), the remaining stable part balanced-truncated to reduced_order − 1 states.
  double integral_gain = 0.0;  ///< k_i [A/(°·s)]
  StateSpace stable_part;      ///< K_s
  double moved_pole = 0.0;     ///< λ, the pole moved to the origin [rad/s]
  Eigen::VectorXd hankel;      ///< Hankel singular values of the stable part before truncation
  /// \brief K_r as one system (integrator first).
  StateSpace reduced() const;
};

/// \brief Designs the H∞ controller of one axis (plant + its current PI gains), THESIS §3.2.3.
/// \throws NumericalError if no γ up to 10⁶ is feasible, or the reduction fails (smallest pole not real, unstable
/// remaining part)
HinfDesign designHinfController(const GalvoPlantParams& plant, const CascadeGains& gains, const HinfConfig& config);
}  // namespace scanhead
