/// \file test_calibration.cpp
/// \brief Calibration of the 30 assembly defects from measured spots (SPEC §4 "Perspective"):
/// the noise generator, the null space named in calibration.hpp, the noise-free fit, the issue 5
/// acceptance (hidden random set, 1 µm noise, table error over the field < 5 µm), the 1σ values
/// against a Monte-Carlo spread, the YAML, options and errors.
#include <gtest/gtest.h>

// GCC 12 reports a false -Wmaybe-uninitialized inside Eigen 3.4's eigensolver.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#include <Eigen/Eigenvalues>
#pragma GCC diagnostic pop
#include <yaml-cpp/yaml.h>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "fixtures/optics_fixture.hpp"
#include "scanhead/common/errors.hpp"
#include "scanhead/optics/calibration.hpp"
#include "scanhead/optics/correction_table.hpp"
#include "scanhead/optics/influence_map.hpp"
#include "scanhead/optics/optical_defects.hpp"

#ifndef SCANHEAD_SOURCE_DIR
#error "SCANHEAD_SOURCE_DIR (repository root) must be defined"
#endif

namespace scanhead
{
namespace
{
const std::string& kUrdfPath = test_support::kNominalUrdfPath;
constexpr int kGrid = 15;           // measurement grid per axis (225 spots)
constexpr double kField_m = 0.175;  // field half width [m] (OpticsConfig default)
constexpr int kTableNodes = 65;     // correction table nodes per axis (SPEC §2.2)
constexpr int kProbes = 41;         // table error probes per axis

const OpticalGeometry& nominal()
{
  return test_support::nominalGeometry();
}

const OpticsConfig& config()
{
  static const OpticsConfig c;
  return c;
}

/// The commanded angles: kGrid × kGrid over the field (influence_map.hpp).
const std::vector<Eigen::Vector2d>& angles()
{
  static const std::vector<Eigen::Vector2d> grid = fieldAngleGrid(OpticalModel(nominal(), config()), kGrid);
  return grid;
}

DefectSet setOf(const std::map<std::string, double>& values)
{
  DefectSet set;
  for (const auto& [label, value] : values)
    set.values[defectIndex(label)] = value;
  return set;
}

/// Spots of a machine at angles() stacked (x0, y0, x1, ...) [m].
Eigen::VectorXd spots(const DefectSet& set)
{
  const OpticalModel model(applyDefects(nominal(), set), config());
  Eigen::VectorXd out(2 * static_cast<Eigen::Index>(angles().size()));
  for (std::size_t k = 0; k < angles().size(); ++k)
    out.segment<2>(2 * static_cast<Eigen::Index>(k)) = model.spot(angles()[k]);
  return out;
}

/// Max over the field of the spot error of a bicubic 65 × 65 table built on \p table_model and
/// run on \p machine [m].
double tableError(const OpticalModel& table_model, const OpticalModel& machine)
{
  const CorrectionTable table = CorrectionTable::build(table_model, kTableNodes, kField_m);
  return measureTableError(table, TableInterpolation::Bicubic, machine, kProbes).max_error_m;
}

// --- noise -------------------------------------------------------------------------------------

TEST(Calibration, NoiseIsSplitmix64ThenBoxMuller)
{
  // Published splitmix64 outputs for seed 0 (Vigna's reference splitmix64.c): 0xe220a8397b1dcdaf,
  // 0x6e789e6aa1b965f4. The first spot's noise is then Box–Muller of u = (top 53 bits + 1)·2⁻⁵³.
  const OpticalModel machine(nominal(), config());
  const std::vector<Eigen::Vector2d> one = {Eigen::Vector2d(0.01, -0.02)};
  const double noise = 1e-6;
  const std::vector<SpotMeasurement> m = simulateMeasurements(machine, one, noise, 0);
  ASSERT_EQ(m.size(), 1u);
  const double u1 = (static_cast<double>(0xe220a8397b1dcdafULL >> 11) + 1.0) / 9007199254740992.0;
  const double u2 = (static_cast<double>(0x6e789e6aa1b965f4ULL >> 11) + 1.0) / 9007199254740992.0;
  const double radius = std::sqrt(-2.0 * std::log(u1));
  constexpr double kTwoPi = 6.283185307179586;
  const Eigen::Vector2d expected = noise * radius * Eigen::Vector2d(std::cos(kTwoPi * u2), std::sin(kTwoPi * u2));
  const Eigen::Vector2d drawn = m[0].spot_m - machine.spot(one[0]);
  // 1e-16 m = 1e-10 of σ: the rounding of the spot (ulp 3.5e-18 m at 30 mm) and of libm; any
  // other generator, order of draws or mapping to (0, 1] would differ by ~σ
  EXPECT_NEAR(drawn.x(), expected.x(), 1e-16);
  EXPECT_NEAR(drawn.y(), expected.y(), 1e-16);
  EXPECT_GT(expected.norm(), 0.1 * noise);  // a real draw, not a degenerate zero
  EXPECT_EQ(m[0].angles_rad, one[0]);
}

TEST(Calibration, NoiseIsGaussianWithTheRequestedSigmaAndReproducible)
{
  const OpticalModel machine(nominal(), config());
  const std::vector<Eigen::Vector2d> same(4000, Eigen::Vector2d(0.05, 0.03));
  const Eigen::Vector2d exact = machine.spot(same[0]);
  const double sigma = 1e-6;
  const std::vector<SpotMeasurement> a = simulateMeasurements(machine, same, sigma, 42);
  const std::vector<SpotMeasurement> b = simulateMeasurements(machine, same, sigma, 42);
  const std::vector<SpotMeasurement> c = simulateMeasurements(machine, same, sigma, 43);
  const std::vector<SpotMeasurement> none = simulateMeasurements(machine, same, 0.0, 42);
  Eigen::Vector2d sum = Eigen::Vector2d::Zero(), sum2 = Eigen::Vector2d::Zero();
  int beyond_3_sigma = 0, differ = 0;
  for (std::size_t k = 0; k < same.size(); ++k)
  {
    ASSERT_EQ(a[k].spot_m, b[k].spot_m) << "same seed, same draws";
    ASSERT_EQ(none[k].spot_m, exact) << "no noise: the exact spot";
    differ += a[k].spot_m != c[k].spot_m;
    const Eigen::Vector2d e = a[k].spot_m - exact;
    sum += e;
    sum2 += e.cwiseProduct(e);
    beyond_3_sigma += (std::abs(e.x()) > 3 * sigma) + (std::abs(e.y()) > 3 * sigma);
  }
  EXPECT_EQ(differ, 4000) << "another seed, other draws";
  const double n = static_cast<double>(same.size());
  for (int axis = 0; axis < 2; ++axis)
  {
    // mean: standard error σ/√n = 1.6e-8 m; 5 standard errors
    EXPECT_LT(std::abs(sum[axis] / n), 5.0 * sigma / std::sqrt(n)) << axis;
    // standard deviation: standard error σ/√(2n) = 1.1 %; 5 %
    EXPECT_NEAR(std::sqrt(sum2[axis] / n), sigma, 0.05 * sigma) << axis;
  }
  // Gaussian tails: P(|e| > 3σ) = 0.27 %, 21.6 expected of 8000 (Poisson σ 4.6); a uniform of the
  // same σ would give 0, a heavy tail far more
  EXPECT_GT(beyond_3_sigma, 6);
  EXPECT_LT(beyond_3_sigma, 40);
}

// --- the null space named in calibration.hpp --------------------------------------------------

TEST(Calibration, NamedNullCombinationsLeaveEverySpotUnchanged)
{
  const Eigen::VectorXd base = spots(DefectSet());
  const double t = 0.1;  // mm | mrad: the defect size of OPT table 2
  const std::map<std::string, std::map<std::string, double>> nulls = {
      {"x translation", {{"work_plane.x", t}, {"axis_x.y", t}}},
      {"y translation", {{"work_plane.y", t}, {"source.y", t}, {"axis_x.z", -t}, {"axis_y.z", t}}},
      {"z translation", {{"work_plane.z", t}, {"source.z", t}, {"axis_y.y", -t}}},
      {"galvo X offset", {{"axis_x.a", t}, {"mirror_x.b", -t}}},
      {"galvo Y offset", {{"axis_y.a", t}, {"mirror_y.b", -t}}},
      {"window a difference", {{"window_1.a", t}, {"window_2.a", -t}}},
      {"window b difference", {{"window_1.b", t}, {"window_2.b", -t}}},
  };
  for (const auto& [name, values] : nulls)
  {
    const double change = (spots(setOf(values)) - base).cwiseAbs().maxCoeff();
    // 1e-10 m: the second-order remainders (e_m·α²/2 = 1.3e-11 m for the offsets, ~6e-12 m for
    // the windows, rounding for the translations); each defect alone moves spots by ≥ 0.1 µm
    EXPECT_LT(change, 1e-10) << name;
    for (const auto& [label, value] : values)
    {
      const double alone = (spots(setOf({{label, value}})) - base).cwiseAbs().maxCoeff();
      EXPECT_GT(alone, 1e-7) << name << ": " << label << " alone";
    }
  }
}

// --- noise-free fit ----------------------------------------------------------------------------

TEST(Calibration, NoiseFreeOptTable2IsFitAndItsIdentifiablePartRecovered)
{
  const DefectSet truth = optTable2DefectSet();
  const OpticalModel machine(applyDefects(nominal(), truth), config());
  const std::vector<SpotMeasurement> m = simulateMeasurements(machine, angles(), 0.0, 1);
  const CalibrationResult result = calibrate(nominal(), config(), m, CalibrationOptions());

  EXPECT_TRUE(result.converged);
  EXPECT_LE(result.iterations, 6);  // measured 3 (mildly non-linear)
  // 1e-9 m: the spec; measured RMS 2.6e-11, max 1.0e-10 (the truth's near-null part, unmodelled)
  EXPECT_LT(result.rms_residual_m, 1e-9);
  EXPECT_LT(result.max_residual_m, 1e-9);

  // rank 16 of 30 (calibration.hpp: 10 exact and 4 near-null directions)
  EXPECT_EQ(result.rank, 16);
  ASSERT_EQ(result.singular_values.size(), kDefectCount);
  EXPECT_TRUE(std::is_sorted(result.singular_values.rbegin(), result.singular_values.rend()));
  const double s0 = result.singular_values[0];
  EXPECT_GT(result.singular_values[15], 1e-5 * s0);  // measured 3.5e-5: the weakest identifiable
  EXPECT_LT(result.singular_values[16], 1e-6 * s0);  // measured 1.5e-7: the first near-null
  EXPECT_LT(result.singular_values[20], 1e-9 * s0);  // measured ≤ 2e-11: exact null directions
  ASSERT_EQ(result.null_space.size(), kDefectCount - 16);
  // the three translations (calibration.hpp), whose rows the echelon form gives exactly
  for (const char* expected :
       {"0.71 work_plane.x + 0.71 axis_x.y", "0.50 work_plane.y + 0.50 source.y - 0.50 axis_x.z + 0.50 axis_y.z",
        "0.58 work_plane.z + 0.58 source.z - 0.58 axis_y.y"})
  {
    EXPECT_NE(std::find(result.null_space.begin(), result.null_space.end(), expected), result.null_space.end())
        << expected;
  }

  // Independent check of "estimate ≡ truth in the identifiable subspace" and of "minimum
  // norm": J by central differences here, its row space from the eigenvectors of JᵀJ (eigenvalues
  // above (1e-6)²·max: the same rank criterion), P the projector onto it.
  auto rowSpace = [](const DefectSet& at, int& rank) {
    Eigen::MatrixXd j(2 * static_cast<Eigen::Index>(angles().size()), static_cast<Eigen::Index>(kDefectCount));
    for (std::size_t i = 0; i < kDefectCount; ++i)
    {
      DefectSet plus = at, minus = at;
      plus.values[i] += 1e-3;
      minus.values[i] -= 1e-3;
      j.col(static_cast<Eigen::Index>(i)) = (spots(plus) - spots(minus)) / 2e-3;
    }
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(j.transpose() * j);
    const Eigen::VectorXd lambda = eigen.eigenvalues();  // ascending
    Eigen::MatrixXd projector = Eigen::MatrixXd::Zero(j.cols(), j.cols());
    rank = 0;
    for (Eigen::Index i = 0; i < lambda.size(); ++i)
    {
      if (lambda[i] > 1e-12 * lambda[lambda.size() - 1])
      {
        projector += eigen.eigenvectors().col(i) * eigen.eigenvectors().col(i).transpose();
        ++rank;
      }
    }
    return projector;
  };
  Eigen::VectorXd estimate(static_cast<Eigen::Index>(kDefectCount)), difference(estimate.size());
  for (std::size_t i = 0; i < kDefectCount; ++i)
  {
    estimate[static_cast<Eigen::Index>(i)] = result.estimate.values[i];
    difference[static_cast<Eigen::Index>(i)] = result.estimate.values[i] - truth.values[i];
  }
  int rank_at_truth = 0, rank_at_estimate = 0;
  const Eigen::MatrixXd at_truth = rowSpace(truth, rank_at_truth);
  const Eigen::MatrixXd at_estimate = rowSpace(result.estimate, rank_at_estimate);
  EXPECT_EQ(rank_at_truth, 16);
  EXPECT_EQ(rank_at_estimate, 16);
  // 3e-5 mm | mrad: the set of equivalent machines is curved (second-order terms of 0.1 mrad
  // rotations over 0.7 m lever arms, ~1e-5) and the near-null part of the truth is not fitted;
  // measured 2.8e-6. The difference itself is large (it lies along the null space).
  EXPECT_LT((at_truth * difference).cwiseAbs().maxCoeff(), 3e-5);
  EXPECT_GT(difference.cwiseAbs().maxCoeff(), 0.01);
  // Minimum norm: no component along the null space at the estimate. 2e-7: measured 1.4e-8 (the
  // accuracy of the eigenvectors of JᵀJ here, ~ε·λ_max/gap); without the null-space pull of the
  // iteration it is 8.8e-6 (the row space turns by ~1e-4 between the nominal and the estimate).
  const Eigen::VectorXd null_part = estimate - at_estimate * estimate;
  EXPECT_LT(null_part.cwiseAbs().maxCoeff(), 2e-7);

  // The estimate is a different machine with the same spots: a table built on it is exact on the
  // true machine (bicubic interpolation error 0.05 nm; measured 1e-10 m).
  const OpticalModel estimated(applyDefects(nominal(), result.estimate), config());
  EXPECT_LT(tableError(estimated, machine), 1e-8);
}

// --- acceptance (issue 5) ----------------------------------------------------------------------

TEST(Calibration, HiddenRandomSetWith1umNoiseCorrectsTheFieldBelow5um)
{
  // A random machine within ±0.1 mm / ±0.1 mrad (OPT's bounds); seeds 1..10 measured in
  // calibration.hpp: uncorrected 127–398 µm, corrected 0.38–0.90 µm.
  const DefectSet truth = randomDefectSet(3, 0.1, 0.1);
  const OpticalModel machine(applyDefects(nominal(), truth), config());
  const double noise = 1e-6;
  const std::vector<SpotMeasurement> m = simulateMeasurements(machine, angles(), noise, 1003);
  CalibrationOptions options;
  options.noise_m = noise;
  const CalibrationResult result = calibrate(nominal(), config(), m, options);
  EXPECT_TRUE(result.converged);
  EXPECT_EQ(result.rank, 16);
  EXPECT_EQ(result.null_space.size(), kDefectCount - 16);
  // Residual = the noise: per spot RMS σ√2·√(1 − 16/450) = 1.389 µm, ±3.4 % standard error;
  // ±15 % (measured 1.344 µm). A poor fit would leave tens of µm.
  EXPECT_NEAR(result.rms_residual_m, 1.389e-6, 0.15 * 1.389e-6);

  const double uncorrected = tableError(OpticalModel(nominal(), config()), machine);
  const double corrected = tableError(OpticalModel(applyDefects(nominal(), result.estimate), config()), machine);
  RecordProperty("uncorrected_um", std::to_string(uncorrected * 1e6));
  RecordProperty("corrected_um", std::to_string(corrected * 1e6));
  EXPECT_GT(uncorrected, 100e-6);  // measured 357 µm: the defects matter
  EXPECT_LT(corrected, 5e-6);      // the acceptance; measured 0.41 µm
}

// --- uncertainties -----------------------------------------------------------------------------

TEST(Calibration, StdDevMatchesTheMonteCarloSpread)
{
  // One machine, 40 noise draws: the spread of each value identifiable on its own must match
  // its reported 1σ (standard error of a 40-sample σ: 11 %; bounds ±35 %, 3 standard errors).
  // Measured spread / 1σ: mirror_x.z 0.286 / 0.301 mm, mirror_x.a 0.401 / 0.410 mrad,
  // mirror_y.z 0.113 / 0.111 mm, mirror_y.a 0.146 / 0.153 mrad.
  const DefectSet truth = randomDefectSet(5, 0.1, 0.1);
  const OpticalModel machine(applyDefects(nominal(), truth), config());
  CalibrationOptions options;
  options.noise_m = 1e-6;
  const int draws = 40;
  std::array<double, kDefectCount> sum{}, sum2{};
  CalibrationResult last;
  for (int k = 0; k < draws; ++k)
  {
    last = calibrate(nominal(), config(), simulateMeasurements(machine, angles(), options.noise_m, 500 + k), options);
    for (std::size_t i = 0; i < kDefectCount; ++i)
    {
      sum[i] += last.estimate.values[i];
      sum2[i] += last.estimate.values[i] * last.estimate.values[i];
    }
  }
  const std::vector<std::string> alone = {"mirror_x.z", "mirror_x.a", "mirror_y.z", "mirror_y.a"};
  for (std::size_t i = 0; i < kDefectCount; ++i)
  {
    const std::string label = defectLabel(i);
    const bool identifiable = std::find(alone.begin(), alone.end(), label) != alone.end();
    if (!identifiable)
    {
      EXPECT_EQ(last.std_dev[i], 0.0) << label << ": entangled in the null space";
      continue;
    }
    const double mean = sum[i] / draws;
    const double spread = std::sqrt((sum2[i] - draws * mean * mean) / (draws - 1));
    EXPECT_GT(last.std_dev[i], 0.0) << label;
    EXPECT_NEAR(spread / last.std_dev[i], 1.0, 0.35) << label << ": spread " << spread << ", 1σ " << last.std_dev[i];
    // unbiased: |mean − truth| within 4 standard errors of the mean (+ the 1e-3 null-space share)
    EXPECT_LT(std::abs(mean - truth.values[i]), 4.0 * last.std_dev[i] / std::sqrt(draws) + 1e-3) << label;
  }
}

// --- YAML --------------------------------------------------------------------------------------

TEST(Calibration, YamlParsesBackAndItsEstimateIsADefectSet)
{
  const OpticalModel machine(applyDefects(nominal(), randomDefectSet(9, 0.1, 0.1)), config());
  CalibrationOptions options;
  const CalibrationResult result =
      calibrate(nominal(), config(), simulateMeasurements(machine, angles(), 1e-6, 9), options);
  const std::string text = calibrationYaml(result);
  const YAML::Node root = YAML::Load(text);
  EXPECT_EQ(root["rank"].as<int>(), result.rank);
  EXPECT_EQ(root["iterations"].as<int>(), result.iterations);
  EXPECT_EQ(root["converged"].as<bool>(), result.converged);
  EXPECT_DOUBLE_EQ(root["rms_residual_um"].as<double>(), result.rms_residual_m * 1e6);
  EXPECT_DOUBLE_EQ(root["max_residual_um"].as<double>(), result.max_residual_m * 1e6);
  ASSERT_EQ(root["singular_values_m_per_unit"].size(), kDefectCount);
  for (std::size_t i = 0; i < kDefectCount; ++i)
    EXPECT_EQ(root["singular_values_m_per_unit"][i].as<double>(), result.singular_values[i]) << i;  // 17 digits
  ASSERT_EQ(root["null_space"].size(), result.null_space.size());
  for (std::size_t i = 0; i < result.null_space.size(); ++i)
    EXPECT_EQ(root["null_space"][i].as<std::string>(), result.null_space[i]);
  for (std::size_t i = 0; i < kDefectCount; ++i)
  {
    const DefectComponent& c = defectComponents()[i];
    const std::string key(1, c.component);
    EXPECT_EQ(root["estimate"][c.element][key].as<double>(), result.estimate.values[i]) << defectLabel(i);
    EXPECT_EQ(root["std_dev"][c.element][key].as<double>(), result.std_dev[i]) << defectLabel(i);
  }

  // The estimate block is a defect set file: loadDefectSet reads it back bit-exactly.
  const std::string path = ::testing::TempDir() + "/calibration_estimate.yaml";
  {
    YAML::Emitter out;
    out << root["estimate"];
    std::ofstream file(path);
    file << out.c_str() << "\n";
  }
  const DefectSet loaded = loadDefectSet(path);
  EXPECT_EQ(loaded.values, result.estimate.values);
  EXPECT_EQ(loaded.name, result.estimate.name);
  std::remove(path.c_str());
}

// --- options and errors ------------------------------------------------------------------------

TEST(Calibration, RankFollowsTheToleranceAndIterationsAreBounded)
{
  const OpticalModel machine(applyDefects(nominal(), optTable2DefectSet()), config());
  const std::vector<SpotMeasurement> m = simulateMeasurements(machine, angles(), 1e-6, 2);
  for (double tolerance : {3e-4, 1e-6})
  {
    CalibrationOptions options;
    options.rank_tolerance = tolerance;
    const CalibrationResult r = calibrate(nominal(), config(), m, options);
    const auto above = std::count_if(r.singular_values.begin(), r.singular_values.end(),
                                     [&](double s) { return s > tolerance * r.singular_values[0]; });
    EXPECT_EQ(r.rank, above) << tolerance;
    EXPECT_EQ(r.null_space.size(), kDefectCount - static_cast<std::size_t>(r.rank)) << tolerance;
    EXPECT_EQ(r.rank, tolerance == 1e-6 ? 16 : 12) << tolerance;  // s_11/s_0 = 1.3e-3, s_12/s_0 = 1.3e-4
  }
  CalibrationOptions none;
  none.max_iterations = 0;
  const CalibrationResult start = calibrate(nominal(), config(), m, none);
  EXPECT_EQ(start.iterations, 0);
  EXPECT_FALSE(start.converged);
  EXPECT_TRUE(start.estimate.isNominal());
  EXPECT_GT(start.max_residual_m, 100e-6);  // the uncorrected machine (OPT table 2: ~260 µm)
}

TEST(Calibration, BadInputsThrow)
{
  const OpticalModel machine(nominal(), config());
  const std::vector<SpotMeasurement> m = simulateMeasurements(machine, angles(), 0.0, 1);
  CalibrationOptions bad;
  bad.rank_tolerance = 0.0;
  EXPECT_THROW(calibrate(nominal(), config(), m, bad), ConfigError);
  bad = CalibrationOptions();
  bad.max_iterations = -1;
  EXPECT_THROW(calibrate(nominal(), config(), m, bad), ConfigError);
  bad = CalibrationOptions();
  bad.noise_m = -1e-6;
  EXPECT_THROW(calibrate(nominal(), config(), m, bad), ConfigError);
  EXPECT_THROW(calibrate(nominal(), config(), {}, CalibrationOptions()), InputError);
  const std::vector<SpotMeasurement> few(m.begin(), m.begin() + 14);  // 28 coordinates for 30 unknowns
  EXPECT_THROW(calibrate(nominal(), config(), few, CalibrationOptions()), InputError);
  std::vector<SpotMeasurement> nan_spot = m;
  nan_spot[3].spot_m.x() = std::nan("");
  EXPECT_THROW(calibrate(nominal(), config(), nan_spot, CalibrationOptions()), InputError);
  EXPECT_THROW(simulateMeasurements(machine, angles(), -1e-6, 1), ConfigError);
  // a commanded angle at which the ray misses the plane (mirror X turned by 1.5 rad)
  std::vector<SpotMeasurement> miss = m;
  miss[0].angles_rad = Eigen::Vector2d(1.5, 0.0);
  EXPECT_THROW(calibrate(nominal(), config(), miss, CalibrationOptions()), NumericalError);
}
}  // namespace
}  // namespace scanhead
