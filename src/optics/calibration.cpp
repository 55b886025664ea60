/// \file calibration.cpp
/// \brief Levenberg–Marquardt on the 30 defects with Eigen's SVD; the derivation, the null space
/// and the measured figures are in calibration.hpp.
// GCC 12 reports a false -Wmaybe-uninitialized inside Eigen 3.4's Householder products (the QR
// step of JacobiSVD); the pragma covers Eigen's headers only, so they come first (as in
// test_calibration.cpp).
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#include <Eigen/Dense>
#pragma GCC diagnostic pop

#include "scanhead/optics/calibration.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "scanhead/common/errors.hpp"
#include "scanhead/common/number_text.hpp"
#include "scanhead/common/random.hpp"

namespace scanhead
{
namespace
{
constexpr Eigen::Index kN = static_cast<Eigen::Index>(kDefectCount);
constexpr double kDifferenceStep = 1e-3;     ///< central-difference step [mm | mrad]
constexpr double kStepTolerance = 1e-9;      ///< stop: max |Δδ| of the range step below this [mm | mrad]
constexpr double kGradientTolerance = 1e-6;  ///< stop: ‖U_ρᵀ r‖ ≤ this · ‖r‖ (r ⟂ identifiable directions)
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
    : nominal_(nominal)
    , config_(config)
    , measurements_(measurements)
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
  Eigen::MatrixXd u;  ///< rows × 30: left singular vectors (only the first rank are used)
  Eigen::VectorXd s;  ///< 30, descending [m per mm | mrad]
  Eigen::MatrixXd v;  ///< 30 × 30
  Eigen::Index rank = 0;
};

/// SVD of J (calibration.hpp: Eigen's JacobiSVD, thin U and V, singular values descending) and
/// the rank: the number of s_i > rank_tolerance · s_0.
Decomposition decompose(const Eigen::MatrixXd& j, double rank_tolerance)
{
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(j, Eigen::ComputeThinU | Eigen::ComputeThinV);
  Decomposition d;
  d.u = svd.matrixU();
  d.s = svd.singularValues();
  d.v = svd.matrixV();
  const double threshold = rank_tolerance * (d.s.size() > 0 ? d.s[0] : 0.0);
  while (d.rank < d.s.size() && d.s[d.rank] > threshold)
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
  std::stable_sort(order.begin(), order.end(), [&](Eigen::Index x, Eigen::Index y) { return printed(x) > printed(y); });
  order.insert(order.begin(), pivot);
  std::string text;
  for (Eigen::Index c : order)
  {
    const std::string label = defectLabel(static_cast<std::size_t>(c));
    if (text.empty())
      text = (v[c] < 0.0 ? "-" : "") + fixedText(std::abs(v[c]), 2) + " " + label;
    else
      text += (v[c] < 0.0 ? " - " : " + ") + fixedText(std::abs(v[c]), 2) + " " + label;
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
  // splitmix64 (random.hpp): fully specified integer arithmetic, then Box–Muller (calibration.hpp).
  SplitMix64 random(seed);
  constexpr double kTwoPi = 6.283185307179586;
  std::vector<SpotMeasurement> out;
  out.reserve(angles.size());
  for (const Eigen::Vector2d& q : angles)
  {
    SpotMeasurement m;
    m.angles_rad = q;
    const double radius = std::sqrt(-2.0 * std::log(random.uniformOpenClosed()));
    const double phase = kTwoPi * random.uniformOpenClosed();
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
