/// \file state_space.cpp
// GCC 12 reports a false -Wmaybe-uninitialized inside Eigen 3.4's triangular and self-adjoint products; the
// pragma covers Eigen's headers only, so they come first (as in src/optics/calibration.cpp).
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#include <Eigen/Dense>
#include <Eigen/Eigenvalues>
#pragma GCC diagnostic pop

#include "scanhead/servo/hinf/state_space.hpp"

#include <cmath>

#include "scanhead/common/errors.hpp"
#include "scanhead/servo/foh_discretisation.hpp"

namespace scanhead
{
Eigen::MatrixXcd StateSpace::response(std::complex<double> s) const
{
  const int n = order();
  if (n == 0)
    return d.cast<std::complex<double>>();
  Eigen::MatrixXcd m = -a.cast<std::complex<double>>();
  m.diagonal().array() += s;
  return c.cast<std::complex<double>>() * m.partialPivLu().solve(b.cast<std::complex<double>>()) +
         d.cast<std::complex<double>>();
}

StateSpace balanceStates(const StateSpace& sys)
{
  StateSpace out = sys;
  const int n = sys.order();
  // Scale state i by f (x_i = f·x̃_i): row i of [A B] divided by f, column i of [A; C] multiplied by f.
  for (int sweep = 0; sweep < 50; ++sweep)
  {
    bool changed = false;
    for (int i = 0; i < n; ++i)
    {
      double col = 0.0, row = 0.0;
      for (int k = 0; k < n; ++k)
        if (k != i)
        {
          col += std::abs(out.a(k, i));
          row += std::abs(out.a(i, k));
        }
      col += out.c.col(i).cwiseAbs().sum();
      row += out.b.row(i).cwiseAbs().sum();
      if (col == 0.0 || row == 0.0)
        continue;
      // The power of two nearest √(row/col) equalises them (f = 2^round(log2 √(row/col))).
      const double f = std::exp2(std::round(0.5 * std::log2(row / col)));
      if (f == 1.0)
        continue;
      out.a.col(i) *= f;
      out.a.row(i) /= f;
      out.c.col(i) *= f;
      out.b.row(i) /= f;
      changed = true;
    }
    if (!changed)
      break;
  }
  return out;
}

Eigen::MatrixXd solveLyapunov(const Eigen::MatrixXd& a, const Eigen::MatrixXd& q)
{
  const Eigen::Index n = a.rows();
  // vec(AX + XAᵀ) = (I ⊗ A + A ⊗ I) vec(X).
  Eigen::MatrixXd k = Eigen::MatrixXd::Zero(n * n, n * n);
  for (Eigen::Index i = 0; i < n; ++i)
    for (Eigen::Index j = 0; j < n; ++j)
    {
      k.block(i * n, j * n, n, n).diagonal().array() += a(i, j);  // A ⊗ I
      if (i == j)
        k.block(i * n, i * n, n, n) += a;  // I ⊗ A
    }
  const Eigen::VectorXd x = k.partialPivLu().solve(-Eigen::Map<const Eigen::VectorXd>(q.data(), n * n));
  const Eigen::MatrixXd xm = Eigen::Map<const Eigen::MatrixXd>(x.data(), n, n);
  return 0.5 * (xm + xm.transpose());
}

namespace
{
/// \brief L with LLᵀ = P for a symmetric positive semi-definite P (eigenvalues below zero by rounding set to 0).
Eigen::MatrixXd squareRootFactor(const Eigen::MatrixXd& p)
{
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(p);
  return eig.eigenvectors() * eig.eigenvalues().cwiseMax(0.0).cwiseSqrt().asDiagonal();
}
}  // namespace

StateSpace balancedTruncation(const StateSpace& sys, int order, Eigen::VectorXd* hankel)
{
  const StateSpace s = balanceStates(sys);
  Eigen::EigenSolver<Eigen::MatrixXd> poles(s.a, false);
  if ((poles.eigenvalues().real().array() >= 0.0).any())
    throw NumericalError("balancedTruncation: the system is not stable");
  const Eigen::MatrixXd p = solveLyapunov(s.a, s.b * s.b.transpose());
  const Eigen::MatrixXd q = solveLyapunov(s.a.transpose(), s.c.transpose() * s.c);
  const Eigen::MatrixXd lc = squareRootFactor(p), lo = squareRootFactor(q);
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(lo.transpose() * lc, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::VectorXd sigma = svd.singularValues();
  if (hankel != nullptr)
    *hankel = sigma;
  if (order > s.order())
    order = s.order();
  if (sigma(order - 1) <= 1e-14 * sigma(0))
    throw NumericalError("balancedTruncation: the kept states are not all controllable and observable");
  const Eigen::VectorXd inv_root = sigma.head(order).cwiseSqrt().cwiseInverse();
  const Eigen::MatrixXd t = lc * svd.matrixV().leftCols(order) * inv_root.asDiagonal();
  const Eigen::MatrixXd ti = inv_root.asDiagonal() * svd.matrixU().leftCols(order).transpose() * lo.transpose();
  return StateSpace{ti * s.a * t, ti * s.b, s.c * t, s.d};
}

StateSpace triangleHold(const StateSpace& sys, double period_s)
{
  const int n = sys.order();
  const FohDiscretisation foh = discretiseFoh(sys.a, sys.b, period_s);
  StateSpace out;
  out.a = foh.phi;
  out.b = foh.gamma1 + (foh.phi - Eigen::MatrixXd::Identity(n, n)) * foh.gamma2;
  out.c = sys.c;
  out.d = sys.d + sys.c * foh.gamma2;
  return out;
}
}  // namespace scanhead
