/// \file calibration.hpp
/// \brief Recovering a machine's assembly defects from measured spot positions (SPEC §4, the OPT
/// paper's perspective): Levenberg–Marquardt on the 30 defects, with the identifiable subspace.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "scanhead/optics/defect_catalog.hpp"
#include "scanhead/optics/optical_model.hpp"

namespace scanhead
{
/// \brief A spot measured on the bed at commanded angles.
struct SpotMeasurement
{
  Eigen::Vector2d angles_rad = Eigen::Vector2d::Zero();  ///< commanded (θx, θy)
  Eigen::Vector2d spot_m = Eigen::Vector2d::Zero();      ///< measured spot, work-plane frame
};

/// \brief Spots of \p machine at \p angles plus independent Gaussian noise of standard deviation
/// \p noise_m per coordinate (portable generator seeded by \p seed: same on every platform).
/// \throws ConfigError if noise_m is negative or not finite
std::vector<SpotMeasurement> simulateMeasurements(const OpticalModel& machine, const std::vector<Eigen::Vector2d>& angles,
                                                  double noise_m, std::uint64_t seed);

struct CalibrationOptions
{
  int max_iterations = 50;
  double rank_tolerance = 1e-6;   ///< singular values below this × the largest are not identifiable
  double noise_m = 1e-6;          ///< measurement noise assumed for the uncertainties [m]
};

struct CalibrationResult
{
  DefectSet estimate;                          ///< minimum-norm solution in the identifiable subspace
  std::array<double, kDefectCount> std_dev{};  ///< 1σ of each value (mm or mrad); 0 where not identifiable on its own
  int rank = 0;                                ///< of the (scaled) Jacobian, out of 30
  std::vector<double> singular_values;         ///< descending, of the Jacobian in m per (mm | mrad)
  /// The unidentifiable combinations: unit null-space vectors of the Jacobian as text, e.g.
  /// "0.71 source.y - 0.71 work_plane.y" (moving along them leaves every spot unchanged).
  std::vector<std::string> null_space;
  double rms_residual_m = 0.0;                 ///< fit residual over the measurements [m]
  double max_residual_m = 0.0;
  int iterations = 0;
  bool converged = false;
};

/// \brief Estimates the defects of the machine that produced \p measurements, starting from the
/// nominal set: LM on r_k(δ) = h_δ(θ_k) − x_k with the Jacobian by central differences, steps
/// restricted to the identifiable subspace (truncated SVD), uncertainties from σ²(JᵀJ)⁺.
/// \throws NumericalError if the model cannot be evaluated (a defect so large the ray misses);
/// ConfigError on bad options; InputError without measurements
CalibrationResult calibrate(const OpticalGeometry& nominal, const OpticsConfig& config,
                            const std::vector<SpotMeasurement>& measurements, const CalibrationOptions& options);

/// \brief The result as YAML (values in mm/mrad with 1σ, rank, singular values, null space, residuals).
std::string calibrationYaml(const CalibrationResult& result);
}  // namespace scanhead
