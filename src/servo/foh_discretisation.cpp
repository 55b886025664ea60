/// \file foh_discretisation.cpp
#include "scanhead/servo/foh_discretisation.hpp"

#include <unsupported/Eigen/MatrixFunctions>

#include <cmath>
#include <sstream>

#include "scanhead/common/errors.hpp"

namespace scanhead
{
FohDiscretisation discretiseFoh(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b, double period_s)
{
  const Eigen::Index n = a.rows();
  const Eigen::Index m = b.cols();
  if (a.cols() != n || b.rows() != n || n == 0 || m == 0)
  {
    std::ostringstream msg;
    msg << "discretiseFoh: inconsistent sizes A " << a.rows() << "x" << a.cols() << ", B " << b.rows() << "x"
        << b.cols();
    throw NumericalError(msg.str());
  }
  if (!(period_s > 0.0) || !std::isfinite(period_s))
  {
    std::ostringstream msg;
    msg << "discretiseFoh: period_s must be > 0 (got " << period_s << ")";
    throw NumericalError(msg.str());
  }
  // Augmented generator in time normalised by T: d/dσ (x, u, Δu) = (AT x + BT u, Δu, 0).
  Eigen::MatrixXd aug = Eigen::MatrixXd::Zero(n + 2 * m, n + 2 * m);
  aug.topLeftCorner(n, n) = a * period_s;
  aug.block(0, n, n, m) = b * period_s;
  aug.block(n, n + m, m, m).setIdentity();
  const Eigen::MatrixXd e = aug.exp();
  if (!e.allFinite())
  {
    throw NumericalError("discretiseFoh: matrix exponential is not finite");
  }
  FohDiscretisation d;
  d.phi = e.topLeftCorner(n, n);
  d.gamma1 = e.block(0, n, n, m);
  d.gamma2 = e.block(0, n + m, n, m);
  return d;
}
}  // namespace scanhead
