/// \file riccati.hpp
/// \brief The stabilising solution of an algebraic Riccati equation from its Hamiltonian matrix.
#pragma once

#include <Eigen/Core>

namespace scanhead
{
/// \brief X = Ric(H) (Zhou, Doyle & Glover, Robust and Optimal Control, 1996, §13.1): for a Hamiltonian
/// \f$H = \begin{pmatrix} A & R \\ -Q & -A^T \end{pmatrix}\f$ (2n × 2n), the symmetric X with
/// \f$A^TX + XA + XRX + Q = 0\f$ and \f$A + RX\f$ stable, from the stable invariant subspace
/// \f$\mathrm{span}\begin{pmatrix} X_1 \\ X_2 \end{pmatrix}\f$ of H: \f$X = X_2X_1^{-1}\f$.
///
/// The subspace comes from the complex Schur form H = UTUᴴ (Eigen's ComplexSchur), reordered so that the n
/// eigenvalues of negative real part lead the diagonal (adjacent swaps by Givens rotations, as LAPACK's ztrexc),
/// whose first n Schur vectors span it: backward stable, where eigenvectors are not.
/// \return false (X untouched) if H has an eigenvalue within 1e-9·‖H‖ of the imaginary axis, fewer or more than n
/// stable eigenvalues, or a singular X₁ (no stabilising solution: the H∞ γ is too small)
bool stabilisingRiccati(const Eigen::MatrixXd& hamiltonian, Eigen::MatrixXd& x);
}  // namespace scanhead
