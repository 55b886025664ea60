/// \file foh_discretisation.hpp
/// \brief Exact discretisation of a linear system whose input is linear between samples (first-order hold).
#pragma once

#include <Eigen/Core>

namespace scanhead
{
/// \brief Discrete matrices of \f$\dot x = A x + B u\f$ over one period \f$T\f$ with the input
/// interpolated linearly between the samples \f$u_k\f$ and \f$u_{k+1}\f$ (first-order hold):
/// \f[ x_{k+1} = \Phi\,x_k + \Gamma_1\,u_k + \Gamma_2\,(u_{k+1} - u_k), \f]
/// \f[ \Phi = e^{AT},\quad \Gamma_1 = \int_0^T e^{A\tau}d\tau\,B,\quad
///     \Gamma_2 = \int_0^T e^{A(T-\tau)}\,\frac{\tau}{T}\,d\tau\,B. \f]
/// All three come from one matrix exponential of the augmented system (Franklin, Powell &
/// Workman, "Digital Control of Dynamic Systems", §6.3.2, triangle-hold equivalent):
/// \f[ \exp\begin{pmatrix} AT & BT & 0 \\ 0 & 0 & I \\ 0 & 0 & 0 \end{pmatrix}
///     = \begin{pmatrix} \Phi & \Gamma_1 & \Gamma_2 \\ 0 & I & I \\ 0 & 0 & I \end{pmatrix}, \f]
/// the augmented state being (x, u, Δu per period) in time normalised by T.
struct FohDiscretisation
{
  Eigen::MatrixXd phi;     ///< Φ = e^{AT} (n×n)
  Eigen::MatrixXd gamma1;  ///< Γ1, weight of u_k (n×m)
  Eigen::MatrixXd gamma2;  ///< Γ2, weight of the increment u_{k+1} - u_k (n×m)
};

/// \brief Exact first-order-hold discretisation of (A, B) at \p period_s.
/// \param[in] a  n×n state matrix [1/s]
/// \param[in] b  n×m input matrix
/// \param[in] period_s  sample period T > 0 [s]
/// \pre A·T should be of moderate norm (scale the states) for full accuracy of the Padé exponential.
FohDiscretisation discretiseFoh(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b, double period_s);
}  // namespace scanhead
