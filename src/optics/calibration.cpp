/// \file calibration.cpp
/// \brief Recovering the 30 assembly defects from measured spots (SPEC §4 "Perspective", OPT §5).
///
/// Unknowns: δ, the 30 defect values of defectComponents() in mm (x, y, z) and mrad (a, b, c),
/// starting from the nominal machine (δ = 0). Data: N spots x_k measured at commanded angles θ_k.
/// Residuals r_k(δ) = h_δ(θ_k) − x_k [m], 2N of them, with h_δ = OpticalModel(applyDefects(
/// nominal, δ), config).trace(θ).spot (the full non-linear ray trace, no linearisation).
///
/// Jacobian J = ∂r/∂δ [m per mm | mrad] by central differences, step 1e-3 mm | mrad (60 model
/// builds and 60·N traces; ~4 ms for N = 225). Those units are natural: 1 mm of translation and
/// 1 mrad of rotation at ~0.7 m lever arms both move the spot by ~1 mm. Linearity (measured on
/// the 15 × 15 fieldAngleGrid of the tests): the 20 largest singular values of J agree to 3 digits
/// between steps 1e-2, 1e-3 and 1e-4 mm | mrad; the truncation and rounding floor of the
/// differences is ~2e-11 of s_max at step 1e-3 (1e-12 at 1e-2, 1e-10 at 1e-4). The problem is
/// mildly non-linear: for OPT table 2 (spots moved by up to 215 µm) the first-order prediction J·δ
/// misses the true spot change by 29 nm at most (7.5e-5 relative) and J(δ) differs from J(0) by
/// 1.6e-4 relative, so Gauss–Newton converges in 3 iterations (also for ±1 mm / ±1 mrad sets).
///
/// SVD of J (one-sided Jacobi, decompose() below) with singular values s_0 ≥ … ≥ s_29; rank =
/// the number of s_i > rank_tolerance · s_0. Measured on the 15 × 15 grid (at OPT table 2; the
/// same to 3 digits at the nominal machine): s_0 = 5.47e-2 m/unit; s_i/s_0 = 0.99, 0.10, 8.0e-2,
/// 3.8e-2, 2.8e-2, 1.1e-2, 9.1e-3, 5.6e-3, 2.4e-3, 2.2e-3, 1.3e-3, 1.3e-4, 8.6e-5, 4.7e-5,
/// 3.5e-5 for i = 1..15; then 1.5e-7, 7.6e-8, 2.6e-8, 2.7e-9 (four near-null directions); then
/// ≤ 2.1e-11 (ten exact null directions, at the finite-difference floor). With the default
/// tolerance 1e-6 the rank is 16 (clear gap: 3.5e-5 → 1.5e-7), 14 combinations are not
/// identifiable.
///
/// The null space, and why (exact: spots unchanged to ≤ 2e-11 m at 0.1 mm | mrad, measured;
/// test_calibration.cpp asserts < 1e-10 m; signs follow the defect frames of optical_defects.cpp):
///  * 3 rigid translations of the head against the work plane. Spots are measured in the plane
///    frame, so moving the plane by t is moving everything else by −t; the source slides along
///    its own beam and a galvo along its own axis for free (no such defect exists):
///    x: work_plane.x + axis_x.y;  y: work_plane.y + source.y − axis_x.z + axis_y.z;
///    z: work_plane.z + source.z − axis_y.y (equal coefficients).
///  * 3 rigid rotations of the head against the plane (work_plane.a, b, c against source, axis
///    rotations, lever-arm translations and, for a and b, window tilts).
///  * 2 joint offsets: axis.a turns the rotor (an offset of the galvo angle); mirror.b turns the
///    mirror about its own axis parallel to the rotor axis, e_m away: the two differ by a slide of
///    the mirror in its own plane (invisible) and an e_m·α²/2 change of offset (1e-11 m at 0.1 mrad):
///    axis_x.a − mirror_x.b and axis_y.a − mirror_y.b.
///  * 2 window differences: a parallel plate moves the ray by a vector that depends on the ray
///    direction, the plate normal and its thickness only, not on where the plate is; both windows
///    have the same thickness and the ray crosses both with the same direction, so tilting one by
///    +ε and the other by −ε cancels: window_1.a − window_2.a and window_1.b − window_2.b.
/// Near-null (below the tolerance: each changes spots by ≲ 1 nm per mm | mrad beyond what other
/// defects can absorb):
///  * 2 common window tilts: a tilt ε moves the ray by ≈ e_v(1 − n1/n2)·ε ≈ 0.93 µm per mrad,
///    almost uniformly over the field, i.e. like a work-plane translation (so the windows are
///    listed alone, "1.00 window_1.a": their work-plane partners are ~1e-3);
///  * source.c = ε with source.y = −0.1 mm/mrad·ε acts as axis_x.a = ε/2: turning the incoming
///    beam about the vertical line through its hit point on mirror X (0.1 m downstream) turns the
///    reflected beam as a galvo X offset of half the angle would (the rotor axis is e_m/√2 from
///    the hit point: not exact);
///  * axis_x.b = β acts as axis_y.a = −β/2: tilting galvo X about base x (the incoming beam
///    direction) turns the beam between the mirrors about base x, which is galvo Y's axis.
/// The list (CalibrationResult::null_space) is one basis of that space: the reduced row echelon
/// form of the null vectors, pivots taken from the last defect backwards (work plane, windows,
/// mirror Y, ...), each vector normalised, coefficients ≥ 0.01 printed with 2 decimals (0.01
/// rather than 0.1: the 0.09 source.y lever arm of the source.c line matters; equal printed
/// coefficients in table order). Measured (15 × 15 fieldAngleGrid, OPT table 2):
///   0.58 work_plane.c - 0.58 source.c - 0.58 axis_y.b + 0.06 source.y + 0.01 axis_x.y
///   0.47 work_plane.b + 0.47 source.b - 0.47 axis_x.c + 0.47 axis_y.c + 0.33 axis_x.y
///     + 0.05 source.z
///   0.54 work_plane.a - 0.54 axis_x.b - 0.38 source.y + 0.38 axis_x.z - 0.37 axis_y.z
///     + 0.01 source.z
///   0.58 work_plane.z + 0.58 source.z - 0.58 axis_y.y
///   0.50 work_plane.y + 0.50 source.y - 0.50 axis_x.z + 0.50 axis_y.z
///   0.71 work_plane.x + 0.71 axis_x.y
///   1.00 window_2.b;  1.00 window_2.a;  1.00 window_1.b;  1.00 window_1.a
///   0.45 mirror_y.b + 0.89 axis_x.b - 0.02 source.z
///   0.45 axis_y.a + 0.89 axis_x.b - 0.02 source.z
///   0.45 mirror_x.b - 0.89 source.c + 0.09 source.y
///   0.45 axis_x.a - 0.89 source.c + 0.09 source.y
/// (the rotations pick up the joint offsets and window tilts through the other pivots).
/// Identifiable: 16 combinations; on their own only mirror_x.z, mirror_x.a, mirror_y.z,
/// mirror_y.a (less than 1 % of their unit vector in the null space: 0.15 % for the offsets z,
/// ≤ 0.013 % for the tilts a), and those four only weakly (their directions carry the smallest
/// identifiable singular values, s/s_0 ~ 1e-4: a mirror offset looks like a translation of its
/// axis along the normal except for a (1 − cos q) term).
///
/// Levenberg–Marquardt restricted to the identifiable subspace: with J = U S Vᵀ, rank ρ,
/// \f[ \Delta\delta = -\sum_{i<\rho} v_i\,\frac{s_i}{s_i^2 + \lambda}\,u_i^\top r
///     \;-\; N N^\top \delta \f]
/// (N: the 30 − ρ null vectors). The first term is the damped truncated-SVD (pseudo-inverse)
/// step; the second pulls δ along the null space toward the origin (it changes no spot to first
/// order), so the iteration converges to the minimum-norm point of the set of equivalent machines
/// (the classical minimum-norm Gauss–Newton iteration δ ← J⁺(Jδ − r)). λ starts at 1e-10·s_0²,
/// ÷10 on an accepted step (cost not increased), ×10 on a rejected one (give up, not converged,
/// above 1e10·s_0²). J is re-evaluated after every accepted step. Stop (converged) when
/// ‖U_ρᵀ r‖ — the spot change the Gauss–Newton step would make, i.e. the gradient in the data
/// metric — is ≤ 1e-6·‖r‖ or ≤ 1 pm·√N, or when the accepted step is ≤ 1e-9 mm | mrad in every
/// value; at most max_iterations steps. At the end δ −= N Nᵀ δ at the final J (the estimate has
/// no null-space component there) and the residuals are recomputed.
///
/// Uncertainties: Cov = σ² (JᵀJ)⁺ = σ² Σ_{i<ρ} v_i v_iᵀ / s_i², σ = options.noise_m, at the final J.
/// std_dev[i] = √Cov_ii when defect i is identifiable on its own (‖row i of N‖ ≤ 0.01), else 0:
/// the value of an entangled defect is the minimum-norm estimate, meaningless alone (only the
/// identifiable combinations are determined; its diagonal would be the spread of that
/// minimum-norm estimate). With noise_m = 0 every std_dev is 0.
///
/// Residuals: rms_residual_m = √(Σ_k |r_k|² / N) and max_residual_m = max_k |r_k| over the spots
/// (|r_k| the 2-D distance), so for pure Gaussian noise σ per axis the RMS is ≈ σ√2·√(1 − ρ/2N).
///
/// Measured (g++ -O2, urdf/scanhead.urdf, default OpticsConfig, 15 × 15 fieldAngleGrid (θ_max =
/// 0.1195, 0.1228 rad), 65 × 65 bicubic tables built on the nominal / estimated model and
/// measured on the true machine with 41 × 41 probes over ±175 mm):
///   OPT table 2, no noise: 3 iterations, 15 ms; fit residual RMS 2.6e-11 m, max 1.0e-10 m (the
///     near-null part of the truth left unmodelled); table error 264 µm → 0.0001 µm.
///   randomDefectSet(seed, 0.1, 0.1), 1 µm noise (noise seed = seed + 1000): residual RMS
///     1.29–1.48 µm; table error max, uncorrected → corrected [µm]: seed 1: 214 → 0.51;
///     2: 127 → 0.58; 3: 357 → 0.41; 4: 130 → 0.90; 5: 235 → 0.68; 6: 202 → 0.56; 7: 398 → 0.38;
///     8: 172 → 0.64; 9: 390 → 0.60; 10: 369 → 0.88. Each calibration: 3 iterations, ~20 ms.
///   Same, other conditions (seeds 1–3): ±0.5 or ±1 mm|mrad sets (up to 3.6 mm uncorrected):
///     0.41–0.58 µm; 7 × 7 grid: 1.0–1.5 µm; 5 × 5 grid: 1.3–1.7 µm; 5 µm noise: 2.1–2.9 µm.
///   1σ (1 µm noise, seed 5): mirror_x.z 0.30 mm, mirror_x.a 0.41 mrad, mirror_y.z 0.11 mm,
///     mirror_y.a 0.15 mrad (the Monte-Carlo spread over 40 noise draws agrees within 5 %): the
///     individual values are poorly determined, the spots are not.
///
/// calibrationYaml (numbers with 17 significant digits, so they read back bit-exactly; the
/// `estimate` map is a defect set file, loadDefectSet reads it):
/// \code
/// rank: 16
/// iterations: 3
/// converged: true
/// rms_residual_um: 1.34...
/// max_residual_um: 2.99...
/// singular_values_m_per_unit: [0.0546..., 0.0543..., ...]   # 30, descending
/// null_space:
///   - "0.58 work_plane.c - 0.58 source.c - 0.58 axis_y.b + 0.06 source.y + 0.01 axis_x.y"
///   - ...
/// estimate:
///   source: {y: ..., z: ..., b: ..., c: ...}
///   ...
///   work_plane: {x: ..., y: ..., z: ..., a: ..., b: ..., c: ...}
///   name: "calibrated"
/// std_dev:
///   source: {y: 0, z: 0, b: 0, c: 0}
///   ...
/// \endcode
///
/// simulateMeasurements: splitmix64 (Steele, Lea & Flood 2014; pure 64-bit integer arithmetic, so
/// the same draws everywhere) → two uniforms u ∈ (0, 1] from the top 53 bits, + 1 ulp → Box–Muller
/// (n_x, n_y) = √(−2 ln u₁)·(cos 2πu₂, sin 2πu₂): one pair per spot. std::normal_distribution is
/// not used because its algorithm is implementation-defined (libm log/cos may still differ in the
/// last bit between platforms).
#include "scanhead/optics/calibration.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "scanhead/common/errors.hpp"
#include "scanhead/common/number_text.hpp"

namespace scanhead
{
namespace
{
constexpr Eigen::Index kN = static_cast<Eigen::Index>(kDefectCount);
constexpr double kDifferenceStep = 1e-3;        ///< central-difference step [mm | mrad]
constexpr double kStepTolerance = 1e-9;         ///< stop: max |Δδ| of the range step below this [mm | mrad]
constexpr double kGradientTolerance = 1e-6;     ///< stop: ‖U_ρᵀ r‖ ≤ this · ‖r‖ (r ⟂ identifiable directions)
constexpr double kSpotStepTolerance_m = 1e-12;  ///< or ‖U_ρᵀ r‖ ≤ this · √(spots) [m]: 1 pm RMS
constexpr double kInitialDamping = 1e-10;       ///< LM λ at start, × s_0²
constexpr double kMinimumDamping = 1e-16;       ///< × s_0²
constexpr double kMaximumDamping = 1e10;        ///< × s_0²: give up above
constexpr double kEntangledTolerance = 0.01;    ///< ‖e_iᵀN‖ above this: not identifiable alone
constexpr double kPrintedCoefficient = 0.01;    ///< null-space text: coefficients at least this
constexpr double kNullCleanup = 1e-9;           ///< null-space basis entries below this set to 0

DefectSet toSet(const Eigen::VectorXd& p)
{
  DefectSet set;
  set.name = "calibrated";
  for (Eigen::Index i = 0; i < kN; ++i)
    set.values[static_cast<std::size_t>(i)] = p[i];
  return set;
}

/// The measurement model h_δ(θ_k) stacked as (x_0, y_0, x_1, y_1, ...) [m].
class SpotModel
{
public:
  SpotModel(const OpticalGeometry& nominal, const OpticsConfig& config,
            const std::vector<SpotMeasurement>& measurements)
    : nominal_(nominal), config_(config), measurements_(measurements)
  {
  }

  Eigen::Index rows() const { return 2 * static_cast<Eigen::Index>(measurements_.size()); }

  /// Predicted spots of the machine with defects \p p (mm | mrad) into \p out (size rows()).
  /// \throws NumericalError (the ray misses) naming the spot and the defect set
  void predict(const Eigen::VectorXd& p, Eigen::VectorXd& out) const
  {
    const OpticalModel model(applyDefects(nominal_, toSet(p)), config_);
    for (std::size_t k = 0; k < measurements_.size(); ++k)
    {
      try
      {
        out.segment<2>(2 * static_cast<Eigen::Index>(k)) = model.trace(measurements_[k].angles_rad).spot;
      }
      catch (const NumericalError& e)
      {
        throw NumericalError("calibration: the model cannot be evaluated at measurement " + std::to_string(k) +
                             " (angles " + fullPrecisionText(measurements_[k].angles_rad.x()) + ", " +
                             fullPrecisionText(measurements_[k].angles_rad.y()) + " rad) with defects |δ|max = " +
                             fullPrecisionText(p.cwiseAbs().maxCoeff()) + " mm|mrad: " + e.what());
      }
    }
  }

  /// r = h_δ(θ) − x [m].
  Eigen::VectorXd residuals(const Eigen::VectorXd& p) const
  {
    Eigen::VectorXd r(rows());
    predict(p, r);
    for (std::size_t k = 0; k < measurements_.size(); ++k)
      r.segment<2>(2 * static_cast<Eigen::Index>(k)) -= measurements_[k].spot_m;
    return r;
  }

  /// ∂r/∂δ [m per mm | mrad] by central differences of step kDifferenceStep.
  Eigen::MatrixXd jacobian(const Eigen::VectorXd& p) const
  {
    Eigen::MatrixXd j(rows(), kN);
    Eigen::VectorXd plus(rows()), minus(rows());
    for (Eigen::Index i = 0; i < kN; ++i)
    {
      Eigen::VectorXd q = p;
      q[i] = p[i] + kDifferenceStep;
      predict(q, plus);
      q[i] = p[i] - kDifferenceStep;
      predict(q, minus);
      j.col(i) = (plus - minus) / (2.0 * kDifferenceStep);
    }
    return j;
  }

private:
  const OpticalGeometry& nominal_;
  const OpticsConfig& config_;
  const std::vector<SpotMeasurement>& measurements_;
};

/// SVD of J with its numerical rank.
struct Decomposition
{
  Eigen::MatrixXd u;  ///< rows × 30: left singular vectors (zero columns where s = 0)
  Eigen::VectorXd s;  ///< 30, descending [m per mm | mrad]
  Eigen::MatrixXd v;  ///< 30 × 30
  Eigen::Index rank = 0;
};

/// One-sided Jacobi SVD (Hestenes; Demmel & Veselić 1992): plane rotations V make the columns
/// of J·V mutually orthogonal; then s_i = |(J·V)_i| and u_i = (J·V)_i / s_i. Chosen over
/// Eigen::JacobiSVD, whose QR preconditioner trips g++ 12's -Wmaybe-uninitialized inside Eigen
/// 3.4, and over the eigenvalues of JᵀJ, which would square the condition number; it computes
/// small singular values to high relative accuracy (the near-null directions matter here).
Decomposition decompose(const Eigen::MatrixXd& j, double rank_tolerance)
{
  Eigen::MatrixXd a = j;
  Eigen::MatrixXd v = Eigen::MatrixXd::Identity(j.cols(), j.cols());
  const Eigen::Index n = j.cols();
  constexpr double kOrthogonal = 1e-15;  // |a_p·a_q| ≤ this·|a_p||a_q|: orthogonal
  for (int sweep = 0; sweep < 60; ++sweep)
  {
    bool rotated = false;
    for (Eigen::Index p = 0; p + 1 < n; ++p)
    {
      for (Eigen::Index q = p + 1; q < n; ++q)
      {
        const double alpha = a.col(p).squaredNorm();
        const double beta = a.col(q).squaredNorm();
        const double gamma = a.col(p).dot(a.col(q));
        if (alpha == 0.0 || beta == 0.0 || std::abs(gamma) <= kOrthogonal * std::sqrt(alpha * beta))
          continue;
        rotated = true;
        const double zeta = (beta - alpha) / (2.0 * gamma);
        const double t = (zeta >= 0.0 ? 1.0 : -1.0) / (std::abs(zeta) + std::sqrt(1.0 + zeta * zeta));
        const double c = 1.0 / std::sqrt(1.0 + t * t);
        const double s = c * t;
        for (Eigen::MatrixXd* m : { &a, &v })
        {
          const Eigen::VectorXd cp = m->col(p);
          m->col(p) = c * cp - s * m->col(q);
          m->col(q) = s * cp + c * m->col(q);
        }
      }
    }
    if (!rotated)
      break;
  }
  std::vector<Eigen::Index> order(static_cast<std::size_t>(n));
  Eigen::VectorXd norm(n);
  for (Eigen::Index i = 0; i < n; ++i)
  {
    order[static_cast<std::size_t>(i)] = i;
    norm[i] = a.col(i).norm();
  }
  std::stable_sort(order.begin(), order.end(),
                   [&norm](Eigen::Index x, Eigen::Index y) { return norm[x] > norm[y]; });
  Decomposition d;
  d.u = Eigen::MatrixXd::Zero(j.rows(), n);
  d.s.resize(n);
  d.v.resize(n, n);
  for (Eigen::Index i = 0; i < n; ++i)
  {
    const Eigen::Index k = order[static_cast<std::size_t>(i)];
    d.s[i] = norm[k];
    d.v.col(i) = v.col(k);
    if (norm[k] > 0.0)
      d.u.col(i) = a.col(k) / norm[k];
  }
  const double threshold = rank_tolerance * (n > 0 ? d.s[0] : 0.0);
  while (d.rank < n && d.s[d.rank] > threshold)
    ++d.rank;
  return d;
}

/// Projector onto the null space, N Nᵀ.
Eigen::MatrixXd nullProjector(const Decomposition& d)
{
  const Eigen::MatrixXd null = d.v.rightCols(kN - d.rank);
  return null * null.transpose();
}

/// A readable basis of the null space: the reduced row echelon form of Nᵀ with the columns taken
/// from the last defect to the first (work plane, windows, mirror Y, ... : each vector then reads
/// "this downstream defect = a combination of upstream ones"), a column becoming a pivot when its
/// largest entry among the remaining rows exceeds 0.1 of the largest entry left (so no pivot is
/// numerical noise); rows scaled to unit norm, pivot positive, sorted by pivot (last defect first).
std::vector<std::pair<Eigen::Index, Eigen::VectorXd>> readableNullBasis(const Decomposition& d)
{
  const Eigen::Index k = kN - d.rank;
  Eigen::MatrixXd a = d.v.rightCols(k).transpose();  // k × 30
  std::vector<Eigen::Index> pivot;
  Eigen::Index row = 0;
  for (Eigen::Index c = kN - 1; c >= 0 && row < k; --c)
  {
    Eigen::Index best_row = row;
    const double best = a.col(c).tail(k - row).cwiseAbs().maxCoeff(&best_row);
    best_row += row;
    if (best <= 0.1 * a.bottomRows(k - row).cwiseAbs().maxCoeff())
      continue;
    a.row(row).swap(a.row(best_row));
    a.row(row) /= a(row, c);
    for (Eigen::Index r = 0; r < k; ++r)
    {
      if (r != row)
        a.row(r) -= a(r, c) * a.row(row);
    }
    pivot.push_back(c);
    ++row;
  }
  std::vector<std::pair<Eigen::Index, Eigen::VectorXd>> basis;
  for (Eigen::Index i = 0; i < row; ++i)
  {
    Eigen::VectorXd v = a.row(i).transpose();
    for (Eigen::Index c = 0; c < kN; ++c)
    {
      if (std::abs(v[c]) < kNullCleanup)
        v[c] = 0.0;
    }
    basis.emplace_back(pivot[static_cast<std::size_t>(i)], v.normalized());
  }
  return basis;
}

std::string twoDecimals(double v)
{
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.2f", v);
  return buffer;
}

/// "0.71 work_plane.x + 0.71 axis_x.y": the pivot first, then the other coefficients of at least
/// kPrintedCoefficient by decreasing printed |c| (ties in table order).
std::string combinationText(Eigen::Index pivot, const Eigen::VectorXd& v)
{
  std::vector<Eigen::Index> order;
  for (Eigen::Index c = 0; c < kN; ++c)
  {
    if (c != pivot && std::abs(v[c]) >= kPrintedCoefficient)
      order.push_back(c);
  }
  // by the printed |c| (hundredths), ties in table order, so that equal coefficients do not
  // swap places with rounding noise
  auto printed = [&v](Eigen::Index c) { return std::lround(std::abs(v[c]) * 100.0); };
  std::stable_sort(order.begin(), order.end(),
                   [&](Eigen::Index x, Eigen::Index y) { return printed(x) > printed(y); });
  order.insert(order.begin(), pivot);
  std::string text;
  for (Eigen::Index c : order)
  {
    const std::string label = defectLabel(static_cast<std::size_t>(c));
    if (text.empty())
      text = (v[c] < 0.0 ? "-" : "") + twoDecimals(std::abs(v[c])) + " " + label;
    else
      text += (v[c] < 0.0 ? " - " : " + ") + twoDecimals(std::abs(v[c])) + " " + label;
  }
  return text;
}
}  // namespace

std::vector<SpotMeasurement> simulateMeasurements(const OpticalModel& machine,
                                                  const std::vector<Eigen::Vector2d>& angles, double noise_m,
                                                  std::uint64_t seed)
{
  if (!(noise_m >= 0.0) || !std::isfinite(noise_m))
    throw ConfigError("calibration: the measurement noise must be >= 0 (got " + fullPrecisionText(noise_m) + " m)");
  // splitmix64 (Steele, Lea, Flood 2014): fully specified integer arithmetic, then Box–Muller.
  std::uint64_t state = seed;
  auto next = [&state]() {
    state += 0x9E3779B97F4A7C15ULL;
    std::uint64_t z = state;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
    return z ^ (z >> 31);
  };
  // uniform in (0, 1]: the top 53 bits, plus one
  auto uniform = [&next]() { return (static_cast<double>(next() >> 11) + 1.0) * (1.0 / 9007199254740992.0); };
  constexpr double kTwoPi = 6.283185307179586;
  std::vector<SpotMeasurement> out;
  out.reserve(angles.size());
  for (const Eigen::Vector2d& q : angles)
  {
    SpotMeasurement m;
    m.angles_rad = q;
    const double radius = std::sqrt(-2.0 * std::log(uniform()));
    const double phase = kTwoPi * uniform();
    m.spot_m = machine.trace(q).spot + noise_m * radius * Eigen::Vector2d(std::cos(phase), std::sin(phase));
    out.push_back(m);
  }
  return out;
}

CalibrationResult calibrate(const OpticalGeometry& nominal, const OpticsConfig& config,
                            const std::vector<SpotMeasurement>& measurements, const CalibrationOptions& options)
{
  if (options.max_iterations < 0)
    throw ConfigError("calibration.max_iterations must be >= 0 (got " + std::to_string(options.max_iterations) + ")");
  if (!(options.rank_tolerance > 0.0 && options.rank_tolerance < 1.0))
    throw ConfigError("calibration.rank_tolerance must be in (0, 1) (got " + fullPrecisionText(options.rank_tolerance) +
                      ")");
  if (!(options.noise_m >= 0.0) || !std::isfinite(options.noise_m))
    throw ConfigError("calibration.noise_m must be >= 0 (got " + fullPrecisionText(options.noise_m) + ")");
  if (measurements.empty())
    throw InputError("calibration: no spot measurements");
  // 30 unknowns need at least 15 spots (2 coordinates each), or the fit only fits the noise.
  if (2 * measurements.size() < kDefectCount)
    throw InputError("calibration: " + std::to_string(measurements.size()) +
                     " spots for 30 unknowns: measure at least 15 (a grid of 4 x 4 or more)");
  for (std::size_t k = 0; k < measurements.size(); ++k)
  {
    if (!measurements[k].angles_rad.allFinite() || !measurements[k].spot_m.allFinite())
      throw InputError("calibration: measurement " + std::to_string(k) + " is not finite");
  }

  const SpotModel model(nominal, config, measurements);
  const double spots = static_cast<double>(measurements.size());
  Eigen::VectorXd p = Eigen::VectorXd::Zero(kN);
  Eigen::VectorXd r = model.residuals(p);
  double cost = r.squaredNorm();
  CalibrationResult result;

  Decomposition d = decompose(model.jacobian(p), options.rank_tolerance);
  const double s2 = d.s[0] * d.s[0];
  double lambda = kInitialDamping * s2;
  while (true)
  {
    // First-order optimality: ‖U_rᵀ r‖ is the RMS-summed spot change the Gauss–Newton step
    // would make (and the gradient in whitened units); stop when it is negligible absolutely or
    // relative to the residual (r ⟂ the identifiable directions).
    const Eigen::VectorXd ur = d.u.leftCols(d.rank).transpose() * r;
    if (ur.norm() <= std::max(kGradientTolerance * r.norm(), kSpotStepTolerance_m * std::sqrt(spots)))
    {
      result.converged = true;
      break;
    }
    if (result.iterations >= options.max_iterations)
      break;
    ++result.iterations;
    const Eigen::VectorXd null_pull = -nullProjector(d) * p;  // toward the minimum norm
    bool accepted = false;
    while (!accepted && lambda <= kMaximumDamping * s2)
    {
      Eigen::VectorXd range_step = Eigen::VectorXd::Zero(kN);
      for (Eigen::Index i = 0; i < d.rank; ++i)
        range_step -= d.v.col(i) * (d.s[i] / (d.s[i] * d.s[i] + lambda) * ur[i]);
      const Eigen::VectorXd trial = p + range_step + null_pull;
      const Eigen::VectorXd trial_r = model.residuals(trial);
      const double trial_cost = trial_r.squaredNorm();
      if (trial_cost <= cost)
      {
        accepted = true;
        p = trial;
        r = trial_r;
        cost = trial_cost;
        lambda = std::max(lambda / 10.0, kMinimumDamping * s2);
        if (range_step.cwiseAbs().maxCoeff() <= kStepTolerance)
          result.converged = true;
      }
      else
      {
        lambda *= 10.0;
      }
    }
    if (!accepted)
      break;  // no decrease even with the largest damping: not converged
    d = decompose(model.jacobian(p), options.rank_tolerance);
    if (result.converged)
      break;
  }

  // Minimum-norm estimate at the final linearisation: remove what is left along the null space.
  p -= nullProjector(d) * p;
  r = model.residuals(p);

  result.estimate = toSet(p);
  result.rank = static_cast<int>(d.rank);
  result.singular_values.assign(d.s.data(), d.s.data() + d.s.size());
  const Eigen::MatrixXd null = d.v.rightCols(kN - d.rank);
  Eigen::MatrixXd covariance = Eigen::MatrixXd::Zero(kN, kN);
  for (Eigen::Index i = 0; i < d.rank; ++i)
    covariance += d.v.col(i) * d.v.col(i).transpose() / (d.s[i] * d.s[i]);
  covariance *= options.noise_m * options.noise_m;
  for (Eigen::Index i = 0; i < kN; ++i)
  {
    const bool entangled = null.row(i).norm() > kEntangledTolerance;
    result.std_dev[static_cast<std::size_t>(i)] = entangled ? 0.0 : std::sqrt(covariance(i, i));
  }
  for (const auto& [pivot, v] : readableNullBasis(d))
    result.null_space.push_back(combinationText(pivot, v));
  const Eigen::Index n = r.size() / 2;
  result.rms_residual_m = n > 0 ? std::sqrt(r.squaredNorm() / static_cast<double>(n)) : 0.0;
  for (Eigen::Index k = 0; k < n; ++k)
    result.max_residual_m = std::max(result.max_residual_m, r.segment<2>(2 * k).norm());
  return result;
}

std::string calibrationYaml(const CalibrationResult& result)
{
  std::ostringstream out;
  out << "# calibration result: values in mm (x, y, z) and mrad (a, b, c), 1 sigma\n";
  out << "rank: " << result.rank << "\n";
  out << "iterations: " << result.iterations << "\n";
  out << "converged: " << (result.converged ? "true" : "false") << "\n";
  out << "rms_residual_um: " << fullPrecisionText(result.rms_residual_m * 1e6) << "\n";
  out << "max_residual_um: " << fullPrecisionText(result.max_residual_m * 1e6) << "\n";
  out << "singular_values_m_per_unit: [";
  for (std::size_t i = 0; i < result.singular_values.size(); ++i)
    out << (i ? ", " : "") << fullPrecisionText(result.singular_values[i]);
  out << "]\n";
  out << "null_space:" << (result.null_space.empty() ? " []" : "") << "\n";
  for (const std::string& s : result.null_space)
    out << "  - \"" << s << "\"\n";
  auto section = [&out](const char* key, const std::array<double, kDefectCount>& values) {
    out << key << ":\n";
    std::string element;
    for (std::size_t i = 0; i < kDefectCount; ++i)
    {
      const DefectComponent& c = defectComponents()[i];
      if (element != c.element)
      {
        element = c.element;
        out << (i ? "}\n" : "") << "  " << element << ": {";
      }
      else
      {
        out << ", ";
      }
      out << c.component << ": " << fullPrecisionText(values[i]);
    }
    out << "}\n";
  };
  out << "# estimate: a defect set (loadDefectSet format) of the minimum-norm solution\n";
  section("estimate", result.estimate.values);
  out << "  name: \"" << result.estimate.name << "\"\n";
  out << "# std_dev: 1 sigma; 0 = not identifiable on its own (see null_space)\n";
  section("std_dev", result.std_dev);
  return out.str();
}
}  // namespace scanhead
