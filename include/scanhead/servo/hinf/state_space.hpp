/// \file state_space.hpp
/// \brief Continuous and discrete linear systems ẋ = Ax + Bu, y = Cx + Du (or x⁺ = Ax + Bu) and the few
/// operations the H∞ design needs: frequency response, state scaling, Lyapunov equations, balanced truncation and
/// the triangle-hold (first-order-hold) discretisation.
#pragma once

#include <Eigen/Core>
#include <complex>

namespace scanhead
{
/// \brief A linear time-invariant system in state-space form, any number of inputs and outputs.
struct StateSpace
{
  Eigen::MatrixXd a, b, c, d;

  int order() const { return static_cast<int>(a.rows()); }
  int inputs() const { return static_cast<int>(d.cols()); }
  int outputs() const { return static_cast<int>(d.rows()); }
  /// \brief C(sI − A)⁻¹B + D at the complex frequency \p s (s = jω continuous; z = e^{jωT} discrete).
  Eigen::MatrixXcd response(std::complex<double> s) const;
  /// \brief The single-input single-output response at s (inputs() = outputs() = 1).
  std::complex<double> siso(std::complex<double> s) const { return response(s)(0, 0); }
};

/// \brief The same system in the coordinates x = T x̃ with T diagonal (powers of two, so no rounding), chosen so that
/// each state's row of [A B] and column of [A; C] have comparable norms (Parlett–Reinsch balancing of the system
/// matrix). The H∞ synthesis plant spans poles from 0.1 to 5·10⁶ rad/s with states in A, rad and V: balanced, its
/// Hamiltonians' eigenvalues come out accurate. The transfer function is unchanged.
StateSpace balanceStates(const StateSpace& sys);

/// \brief X solving AX + XAᵀ + Q = 0 (A stable, n ≤ ~30: the Kronecker form solved by LU, O(n⁶)).
Eigen::MatrixXd solveLyapunov(const Eigen::MatrixXd& a, const Eigen::MatrixXd& q);

/// \brief Balanced truncation (Moore 1981; square-root form, Laub et al. 1987) of a stable continuous system to
/// \p order states: Gramians P, Q of AP + PAᵀ + BBᵀ = 0, AᵀQ + QA + CᵀC = 0, Hankel singular values σᵢ = √λᵢ(PQ);
/// the states of the smallest σ dropped. Error bound ‖G − Gᵣ‖∞ ≤ 2 Σ_{dropped} σᵢ.
/// \param[out] hankel  the σᵢ of \p sys, decreasing (optional)
/// \throws NumericalError if \p sys is not stable or a Gramian is not positive definite enough to balance
StateSpace balancedTruncation(const StateSpace& sys, int order, Eigen::VectorXd* hankel = nullptr);

/// \brief Triangle-hold equivalent at period T (Franklin, Powell & Workman, Digital Control of Dynamic Systems, §6.3.2;
/// the THESIS discretises its H∞ controllers so, §3.4): the exact response at the samples to an input linear between
/// them. With Φ, Γ1, Γ2 of discretiseFoh (foh_discretisation.hpp), x_{k+1} = Φx_k + Γ1u_k + Γ2(u_{k+1} − u_k) is made
/// causal with ξ_k = x_k − Γ2u_k: ξ⁺ = Φξ + (Γ1 + (Φ − I)Γ2)u, y = Cξ + (D + CΓ2)u. An integrator becomes the
/// trapezoidal rule.
StateSpace triangleHold(const StateSpace& sys, double period_s);
}  // namespace scanhead
