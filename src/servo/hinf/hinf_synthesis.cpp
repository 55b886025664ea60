/// \file hinf_synthesis.cpp
// GCC 12 reports a false -Wmaybe-uninitialized inside Eigen 3.4's triangular and self-adjoint products; the
// pragma covers Eigen's headers only, so they come first (as in src/optics/calibration.cpp).
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#include <Eigen/Dense>
#include <Eigen/Eigenvalues>
#pragma GCC diagnostic pop

#include "scanhead/servo/hinf/hinf_synthesis.hpp"

#include <algorithm>
#include <cmath>

#include "scanhead/common/errors.hpp"
#include "scanhead/servo/hinf/riccati.hpp"

namespace scanhead
{
using Eigen::MatrixXd;

StateSpace synthesisModel(const GalvoPlantParams& p, const CascadeGains& gains)
{
  // States (i, z = ∫(i_ref − i)dt, ω_r, θ, q̃, p); U = K_ii(i_ref − i) + (K_ii/T_ii) z.
  const double wr = 2.0 * M_PI * p.mode_frequency_hz;
  const double kc = p.torque_constant_nm_per_a, l = p.inductance_h;
  StateSpace g;
  g.a = MatrixXd::Zero(6, 6);
  g.b = MatrixXd::Zero(6, 1);
  g.a(0, 0) = (-gains.kii - p.resistance_ohm) / l;
  g.a(0, 1) = gains.kii / gains.tii_s / l;
  g.a(0, 2) = -kc / l;  // back-EMF Ke(ω_r + p), Ke = Kc
  g.a(0, 5) = -kc / l;
  g.b(0, 0) = gains.kii / l;
  g.a(1, 0) = -1.0;
  g.b(1, 0) = 1.0;
  g.a(2, 0) = kc / p.inertia_kgm2;
  g.a(2, 2) = -p.viscous_nms / p.inertia_kgm2;
  g.a(3, 2) = 1.0;
  g.a(3, 5) = 1.0;
  g.a(4, 5) = wr;
  g.a(5, 4) = -wr;
  g.a(5, 5) = -2.0 * p.mode_damping * wr;
  g.a(5, 0) = p.mode_gain;
  g.c = MatrixXd::Zero(1, 6);
  g.c(0, 3) = 180.0 / M_PI;
  g.d = MatrixXd::Zero(1, 1);
  return g;
}

StateSpace standardForm(const StateSpace& g, const HinfConfig& config)
{
  const StateSpace w1 = config.w1.stateSpace(), w2 = config.w2.stateSpace(), w3 = config.w3.stateSpace();
  const int n = g.order(), n1 = n, n2 = n + 1, n3 = n + 2, total = n + 3;
  StateSpace p;
  p.a = MatrixXd::Zero(total, total);
  p.b = MatrixXd::Zero(total, 3);  // r, d, u
  p.c = MatrixXd::Zero(3, total);  // e1, e2, ε
  p.d = MatrixXd::Zero(3, 3);
  // ẋ = A x + B(u + C3 x3 + D3 d)
  p.a.topLeftCorner(n, n) = g.a;
  p.a.block(0, n3, n, 1) = g.b * w3.c;
  p.b.block(0, 1, n, 1) = g.b * w3.d;
  p.b.block(0, 2, n, 1) = g.b;
  // ẋ1 = A1 x1 + B1(r − C x)
  p.a.block(n1, 0, 1, n) = -w1.b * g.c;
  p.a(n1, n1) = w1.a(0, 0);
  p.b(n1, 0) = w1.b(0, 0);
  // ẋ2 = A2 x2 + B2 u
  p.a(n2, n2) = w2.a(0, 0);
  p.b(n2, 2) = w2.b(0, 0);
  // ẋ3 = A3 x3 + B3 d
  p.a(n3, n3) = w3.a(0, 0);
  p.b(n3, 1) = w3.b(0, 0);
  // e1 = C1 x1 + D1(r − C x); e2 = C2 x2 + D2 u; ε = r − C x
  p.c.block(0, 0, 1, n) = -w1.d * g.c;
  p.c(0, n1) = w1.c(0, 0);
  p.d(0, 0) = w1.d(0, 0);
  p.c(1, n2) = w2.c(0, 0);
  p.d(1, 2) = w2.d(0, 0);
  p.c.block(2, 0, 1, n) = -g.c;
  p.d(2, 0) = 1.0;
  return p;
}

namespace
{
double largestSingularValue(const MatrixXd& m)
{
  if (m.size() == 0)
    return 0.0;
  return Eigen::JacobiSVD<MatrixXd>(m).singularValues()(0);
}

/// \brief Symmetric square root factor: M with MMᵀ = S (S positive definite, small).
MatrixXd choleskyFactor(const MatrixXd& s)
{
  Eigen::LLT<MatrixXd> llt(s);
  return llt.matrixL();
}

/// \brief Whether the symmetric X is positive semi-definite up to rounding.
bool positiveSemiDefinite(const MatrixXd& x)
{
  Eigen::SelfAdjointEigenSolver<MatrixXd> eig(x);
  const double scale = std::max(1.0, eig.eigenvalues().cwiseAbs().maxCoeff());
  return eig.eigenvalues().minCoeff() >= -1e-9 * scale;
}
}  // namespace

bool centralController(const StateSpace& p_in, int ny, int nu, double gamma, StateSpace& controller)
{
  const int n = p_in.order();
  const int m1 = p_in.inputs() - nu, p1 = p_in.outputs() - ny;
  if (nu != 1 || ny != 1 || m1 < 1 || p1 < 1)
    throw NumericalError("centralController: one control and one measurement expected");
  // Scale u and y so that D12 = [0; 1], D21 = [0 1]; the exogenous inputs whose D21 is 0 come first.
  StateSpace p = p_in;
  const double d12 = p.d(p1 - 1, m1), d21 = p.d(p1, m1 - 1);
  if (d12 == 0.0 || d21 == 0.0 || p.d.block(0, m1, p1 - 1, 1).cwiseAbs().maxCoeff() > 0.0 ||
      p.d.block(p1, 0, 1, m1 - 1).cwiseAbs().maxCoeff() > 0.0 || p.d(p1, m1) != 0.0)
    throw NumericalError("centralController: D12 must be [0; d], D21 [0 d] and D22 = 0");
  p.b.col(m1) /= d12;
  p.d.col(m1) /= d12;
  p.c.row(p1) /= d21;
  p.d.row(p1) /= d21;
  const int m2 = nu, p2 = ny;
  const MatrixXd& a = p.a;
  const MatrixXd b1 = p.b.leftCols(m1), b2 = p.b.rightCols(m2);
  const MatrixXd c1 = p.c.topRows(p1), c2 = p.c.bottomRows(p2);
  const MatrixXd d11 = p.d.topLeftCorner(p1, m1);
  const MatrixXd d1111 = d11.topLeftCorner(p1 - m2, m1 - p2), d1112 = d11.topRightCorner(p1 - m2, p2);
  const MatrixXd d1121 = d11.bottomLeftCorner(m2, m1 - p2), d1122 = d11.bottomRightCorner(m2, p2);
  MatrixXd d1111_row(p1 - m2, m1), d1111_col(m1 - p2, p1);
  d1111_row << d1111, d1112;
  d1111_col << d1111.transpose(), d1121.transpose();
  if (!(gamma > std::max(largestSingularValue(d1111_row), largestSingularValue(d1111_col))))
    return false;
  const double g2 = gamma * gamma;
  MatrixXd d1dot(p1, m1 + m2), ddot1(p1 + p2, m1);
  d1dot << d11, p.d.topRightCorner(p1, m2);
  ddot1 << d11, p.d.bottomLeftCorner(p2, m1);
  MatrixXd r = d1dot.transpose() * d1dot;
  r.topLeftCorner(m1, m1).diagonal().array() -= g2;
  MatrixXd rt = ddot1 * ddot1.transpose();
  rt.topLeftCorner(p1, p1).diagonal().array() -= g2;
  const MatrixXd ri = r.inverse(), rti = rt.inverse();
  const MatrixXd& b = p.b;
  const MatrixXd& c = p.c;
  // Hamiltonians of X∞ and Y∞.
  MatrixXd h(2 * n, 2 * n), j(2 * n, 2 * n);
  {
    MatrixXd left(2 * n, m1 + m2), right(m1 + m2, 2 * n);
    left << b, -c1.transpose() * d1dot;
    right << d1dot.transpose() * c1, b.transpose();
    h << a, MatrixXd::Zero(n, n), -c1.transpose() * c1, -a.transpose();
    h -= left * ri * right;
  }
  {
    MatrixXd left(2 * n, p1 + p2), right(p1 + p2, 2 * n);
    left << c.transpose(), -b1 * ddot1.transpose();
    right << ddot1 * b1.transpose(), c;
    j << a.transpose(), MatrixXd::Zero(n, n), -b1 * b1.transpose(), -a;
    j -= left * rti * right;
  }
  MatrixXd x, y;
  if (!stabilisingRiccati(h, x) || !positiveSemiDefinite(x))
    return false;
  if (!stabilisingRiccati(j, y) || !positiveSemiDefinite(y))
    return false;
  const Eigen::VectorXcd xy = (x * y).eigenvalues();
  if (!(xy.cwiseAbs().maxCoeff() < g2))
    return false;
  const MatrixXd f = -ri * (d1dot.transpose() * c1 + b.transpose() * x);   // (m1 + m2) × n
  const MatrixXd l = -(b1 * ddot1.transpose() + y * c.transpose()) * rti;  // n × (p1 + p2)
  const MatrixXd f12 = f.middleRows(m1 - p2, p2), f2 = f.bottomRows(m2);
  const MatrixXd l12 = l.middleCols(p1 - m2, m2), l2 = l.rightCols(p2);
  const MatrixXd z = (MatrixXd::Identity(n, n) - y * x / g2).inverse();
  const MatrixXd eye_m1p2 = MatrixXd::Identity(p1 - m2, p1 - m2), eye_m1 = MatrixXd::Identity(m1 - p2, m1 - p2);
  const MatrixXd dh11 =
      -d1121 * d1111.transpose() * (g2 * eye_m1p2 - d1111 * d1111.transpose()).inverse() * d1112 - d1122;
  const MatrixXd dh12 = choleskyFactor(MatrixXd::Identity(m2, m2) -
                                       d1121 * (g2 * eye_m1 - d1111.transpose() * d1111).inverse() * d1121.transpose());
  const MatrixXd dh21 =
      choleskyFactor(MatrixXd::Identity(p2, p2) -
                     d1112.transpose() * (g2 * eye_m1p2 - d1111 * d1111.transpose()).inverse() * d1112)
          .transpose();
  const MatrixXd bh2 = z * (b2 + l12) * dh12;
  const MatrixXd ch2 = -dh21 * (c2 + f12);
  const MatrixXd bh1 = -z * l2 + bh2 * dh12.inverse() * dh11;
  const MatrixXd ch1 = f2 + dh11 * dh21.inverse() * ch2;
  const MatrixXd ah = a + b * f + bh1 * dh21.inverse() * ch2;
  // Undo the scaling of u and y: K = K_n(y/d21)/d12.
  controller.a = ah;
  controller.b = bh1 / d21;
  controller.c = ch1 / d12;
  controller.d = dh11 / (d12 * d21);
  return true;
}

StateSpace synthesisProblem(const GalvoPlantParams& plant, const CascadeGains& gains, const HinfConfig& config)
{
  StateSpace p = balanceStates(standardForm(synthesisModel(plant, gains), config));
  p.b.leftCols(2).rowwise().reverseInPlace();
  p.d.leftCols(2).rowwise().reverseInPlace();
  return p;
}

StateSpace HinfDesign::reduced() const
{
  const int n = stable_part.order() + 1;
  StateSpace k;
  k.a = MatrixXd::Zero(n, n);
  k.a.bottomRightCorner(n - 1, n - 1) = stable_part.a;
  k.b = MatrixXd::Zero(n, 1);
  k.b(0, 0) = integral_gain;
  k.b.bottomRows(n - 1) = stable_part.b;
  k.c = MatrixXd::Zero(1, n);
  k.c(0, 0) = 1.0;
  k.c.rightCols(n - 1) = stable_part.c;
  k.d = stable_part.d;
  return k;
}

namespace
{
/// \brief THESIS step 4: the real pole λ of smallest magnitude moved to the origin, K' = K·(s − λ)/s, written as
/// k_i/s + K_s with K_s stable of order n − 1. With K = D + r/(s − λ) + C₂(sI − A₂)⁻¹B₂ (λ's mode split off by its
/// left and right eigenvectors u, v: r = (Cv)(uᵀB)/(uᵀv), A₂ on the invariant complement u^⊥),
/// K' = D + [r − λ(D + K₂(0))]/s + C₂(sI − A₂)⁻¹(I − λA₂⁻¹)B₂.
void moveSmallestPoleToOrigin(const StateSpace& k, HinfDesign& design)
{
  const StateSpace kb = balanceStates(k);
  const int n = kb.order();
  Eigen::EigenSolver<MatrixXd> eig(kb.a, false);
  Eigen::Index smallest = 0;
  eig.eigenvalues().cwiseAbs().minCoeff(&smallest);
  const std::complex<double> lambda_c = eig.eigenvalues()(smallest);
  if (std::abs(lambda_c.imag()) > 1e-9 * std::abs(lambda_c))
    throw NumericalError("H-infinity reduction: the controller's smallest pole is not real");
  const double lambda = lambda_c.real();
  MatrixXd shifted = kb.a;
  shifted.diagonal().array() -= lambda;
  Eigen::JacobiSVD<MatrixXd> svd(shifted, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::VectorXd v = svd.matrixV().col(n - 1), u = svd.matrixU().col(n - 1);
  const double r = (kb.c * v)(0, 0) * (u.transpose() * kb.b)(0, 0) / u.dot(v);
  // Orthonormal basis W of u^⊥ (A-invariant since uᵀA = λuᵀ).
  const MatrixXd q = Eigen::HouseholderQR<MatrixXd>(u).householderQ() * MatrixXd::Identity(n, n);
  const MatrixXd w = q.rightCols(n - 1);
  const MatrixXd a2 = w.transpose() * kb.a * w;
  const MatrixXd b2 = w.transpose() * (kb.b - v * (u.transpose() * kb.b) / u.dot(v));
  const MatrixXd c2 = kb.c * w;
  const MatrixXd a2_inv_b2 = a2.partialPivLu().solve(b2);
  design.moved_pole = lambda;
  design.integral_gain = r - lambda * (kb.d(0, 0) - (c2 * a2_inv_b2)(0, 0));
  design.stable_part = StateSpace{a2, b2 - lambda * a2_inv_b2, c2, kb.d};
}
}  // namespace

HinfDesign designHinfController(const GalvoPlantParams& plant, const CascadeGains& gains, const HinfConfig& config)
{
  const StateSpace p = synthesisProblem(plant, gains, config);
  HinfDesign design;
  StateSpace k;
  // Bracket: γ_low below every achievable level (the D11 bound), γ_high doubled until achievable.
  double low = 0.0, high = 1.0;
  while (!centralController(p, 1, 1, high, k))
  {
    low = high;
    high *= 2.0;
    if (high > 1.0e6)
      throw NumericalError("H-infinity synthesis: no gamma up to 1e6 is achievable with servo.hinf's weights");
  }
  while (high - low > config.gamma_tolerance * high)
  {
    const double mid = 0.5 * (low + high);
    if (centralController(p, 1, 1, mid, k))
      high = mid;
    else
      low = mid;
  }
  centralController(p, 1, 1, high, design.full);
  design.gamma = high;
  design.gamma_lower = low;
  moveSmallestPoleToOrigin(design.full, design);
  design.stable_part = balancedTruncation(design.stable_part, config.reduced_order - 1, &design.hankel);
  return design;
}
}  // namespace scanhead
