/// \file levenberg_marquardt.hpp
/// \brief A small dense Levenberg–Marquardt least-squares solver with Marquardt's diagonal
/// scaling and a central-difference Jacobian (K. Levenberg, "A method for the solution of certain
/// non-linear problems in least squares", Quart. Appl. Math. 2, 1944; D. W. Marquardt, "An
/// algorithm for least-squares estimation of nonlinear parameters", SIAM J. Appl. Math. 11, 1963).
///
/// Knows nothing of the problem: the caller gives the residual vector as a function of the
/// parameters (used by the galvo identification's transfer-function fits).
#pragma once

#include <algorithm>
#include <cmath>

#include <Eigen/Dense>

namespace scanhead
{
/// \brief Where levenbergMarquardt() stopped.
struct LevenbergMarquardtResult
{
  Eigen::VectorXd x;   ///< the parameters at the lowest cost found
  double cost = 0.0;   ///< \f$C(x) = \sum_k r_k(x)^2\f$ there
  int iterations = 0;  ///< Jacobian evaluations (outer iterations) made
};

/// \brief Minimises \f$C(x) = \|r(x)\|^2\f$ from \p x.
///
/// Each iteration forms the central-difference Jacobian
/// \f[ J_{:,j} = \frac{r(x + h_j e_j) - r(x - h_j e_j)}{2h_j},\qquad h_j = 10^{-6}\max(1, |x_j|), \f]
/// and solves (LDLᵀ) the damped normal equations with Marquardt's scaling,
/// \f[ \left(J^\top J + \lambda\,\mathrm{diag}\big(\max(J^\top J_{jj}, 10^{-30})\big)\right)\delta
///     = -J^\top r. \f]
/// A step is accepted if \f$C(x + \delta)\f$ is finite and below \f$C(x)\f$: then
/// \f$\lambda \leftarrow \max(\lambda/3, 10^{-12})\f$; else \f$\lambda \leftarrow 4\lambda\f$ and the
/// step is solved again, while \f$\lambda < 10^{12}\f$. λ starts at 1e-3.
/// Stops when an accepted step lowered the cost by at most 1e-12 of the new cost or was shorter
/// than 1e-10 (converged), when no damping lowers the cost, or after \p max_iterations.
/// \param[in] residuals  callable \c Eigen::VectorXd(const Eigen::VectorXd&), the residual vector r(x)
/// \param[in] x  initial parameters
/// \param[in] max_iterations  at most this many Jacobian evaluations
template <typename Residuals>
LevenbergMarquardtResult levenbergMarquardt(const Residuals& residuals, Eigen::VectorXd x, int max_iterations)
{
  const Eigen::Index n = x.size();
  Eigen::VectorXd r = residuals(x);
  double cost = r.squaredNorm();
  double lambda = 1e-3;
  int it = 0;
  bool converged = false;
  while (!converged && it < max_iterations)
  {
    ++it;
    Eigen::MatrixXd jac(r.size(), n);
    for (Eigen::Index j = 0; j < n; ++j)
    {
      const double h = 1e-6 * std::max(1.0, std::abs(x[j]));
      Eigen::VectorXd xp = x, xm = x;
      xp[j] += h;
      xm[j] -= h;
      jac.col(j) = (residuals(xp) - residuals(xm)) / (2.0 * h);
    }
    const Eigen::MatrixXd a = jac.transpose() * jac;
    const Eigen::VectorXd g = jac.transpose() * r;
    bool improved = false;
    Eigen::VectorXd step;
    while (lambda < 1e12)
    {
      Eigen::MatrixXd damped = a;
      for (Eigen::Index j = 0; j < n; ++j)
        damped(j, j) += lambda * std::max(a(j, j), 1e-30);
      step = damped.ldlt().solve(-g);
      const Eigen::VectorXd candidate = x + step;
      const Eigen::VectorXd rc = residuals(candidate);
      const double cc = rc.squaredNorm();
      if (std::isfinite(cc) && cc < cost)
      {
        const double decrease = cost - cc;
        x = candidate;
        r = rc;
        cost = cc;
        lambda = std::max(lambda / 3.0, 1e-12);
        improved = true;
        converged = decrease <= 1e-12 * cost || step.norm() < 1e-10;
        break;
      }
      lambda *= 4.0;
    }
    if (!improved)
      break;
  }
  return {x, cost, it};
}
}  // namespace scanhead
