/// \file riccati.cpp
// GCC 12 reports a false -Wmaybe-uninitialized inside Eigen 3.4's triangular and self-adjoint products; the
// pragma covers Eigen's headers only, so they come first (as in src/optics/calibration.cpp).
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#include <Eigen/Dense>
#include <Eigen/Eigenvalues>
#pragma GCC diagnostic pop

#include "scanhead/servo/hinf/riccati.hpp"

#include <cmath>
#include <complex>

namespace scanhead
{
namespace
{
using Complex = std::complex<double>;

/// \brief Swaps the diagonal entries k and k+1 of the upper triangular \p t, updating the Schur vectors \p u
/// (H = UTUᴴ kept). The rotation's first column is the eigenvector of the 2 × 2 block for its second eigenvalue.
void swapAdjacent(Eigen::MatrixXcd& t, Eigen::MatrixXcd& u, Eigen::Index k)
{
  const Complex a = t(k, k), b = t(k + 1, k + 1);
  const Complex v1 = t(k, k + 1), v2 = b - a;
  const double norm = std::hypot(std::abs(v1), std::abs(v2));
  if (norm == 0.0)
    return;  // equal eigenvalues, nothing to reorder
  Eigen::Matrix2cd g;
  g << v1 / norm, -std::conj(v2) / norm, v2 / norm, std::conj(v1) / norm;
  t.middleRows(k, 2) = g.adjoint() * t.middleRows(k, 2);
  t.middleCols(k, 2) = t.middleCols(k, 2) * g;
  u.middleCols(k, 2) = u.middleCols(k, 2) * g;
  t(k + 1, k) = 0.0;
}
}  // namespace

bool stabilisingRiccati(const Eigen::MatrixXd& hamiltonian, Eigen::MatrixXd& x)
{
  const Eigen::Index n2 = hamiltonian.rows(), n = n2 / 2;
  Eigen::ComplexSchur<Eigen::MatrixXcd> schur(hamiltonian.cast<Complex>());
  if (schur.info() != Eigen::Success)
    return false;
  Eigen::MatrixXcd t = schur.matrixT(), u = schur.matrixU();
  const double tiny = 1e-9 * hamiltonian.cwiseAbs().rowwise().sum().maxCoeff();
  Eigen::Index stable = 0;
  for (Eigen::Index i = 0; i < n2; ++i)
  {
    const double re = t(i, i).real();
    if (std::abs(re) <= tiny)
      return false;  // an eigenvalue on the imaginary axis
    stable += re < 0.0 ? 1 : 0;
  }
  if (stable != n)
    return false;
  // Bubble every stable eigenvalue up past the unstable ones before it.
  Eigen::Index placed = 0;
  for (Eigen::Index i = 0; i < n2 && placed < n; ++i)
    if (t(i, i).real() < 0.0)
    {
      for (Eigen::Index k = i; k > placed; --k)
        swapAdjacent(t, u, k - 1);
      ++placed;
    }
  const Eigen::MatrixXcd x1 = u.topLeftCorner(n, n), x2 = u.bottomLeftCorner(n, n);
  Eigen::PartialPivLU<Eigen::MatrixXcd> lu(x1);
  const double rcond = lu.rcond();
  if (!(rcond > 1e-13))
    return false;
  // X = X₂X₁⁻¹ = (X₁⁻ᴴX₂ᴴ)ᴴ: real and symmetric up to rounding.
  const Eigen::MatrixXcd xc = x1.transpose().partialPivLu().solve(x2.transpose()).transpose();
  const Eigen::MatrixXd xr = xc.real();
  x = 0.5 * (xr + xr.transpose());
  return true;
}
}  // namespace scanhead
