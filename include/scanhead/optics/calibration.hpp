/// \file calibration.hpp
/// \brief Recovering a machine's assembly defects from measured spot positions (SPEC §4
/// "Perspective", the OPT paper's §5): Levenberg–Marquardt on the 30 defects, with the
/// identifiable subspace.
///
/// \par Problem
/// Unknowns: δ, the 30 defect values of defectComponents() in mm (x, y, z) and mrad (a, b, c),
/// starting from the nominal machine (δ = 0). Data: N spots x_k measured at commanded angles θ_k.
/// Residuals, 2N of them [m]:
/// \f[ r_k(\delta) = h_\delta(\theta_k) - x_k, \qquad
///     h_\delta = \mathrm{OpticalModel}(\mathrm{applyDefects}(\mathrm{nominal},
///     \delta)).\mathrm{trace}(\theta).\mathrm{spot} \f]
/// (the full non-linear ray trace, no linearisation).
///
/// \par Jacobian
/// By central differences of step h = 1e-3 mm | mrad (60 model builds and 60·N traces; ~4 ms for
/// N = 225):
/// \f[ J_{:,i} = \frac{r(\delta + h e_i) - r(\delta - h e_i)}{2h} \quad [\mathrm{m\ per\ mm} \mid \mathrm{mrad}] \f]
/// Those units are natural: 1 mm of translation and 1 mrad of rotation at ~0.7 m lever arms both
/// move the spot by ~1 mm. Linearity (measured on the 15 × 15 fieldAngleGrid of the tests): the 20
/// largest singular values of J agree to 3 digits between steps 1e-2, 1e-3 and 1e-4 mm | mrad; the
/// truncation and rounding floor of the differences is ~2e-11 of s_max at step 1e-3 (1e-12 at
/// 1e-2, 1e-10 at 1e-4). The problem is mildly non-linear: for OPT table 2 (spots moved by up to
/// 215 µm) the first-order prediction J·δ misses the true spot change by 29 nm at most (7.5e-5
/// relative) and J(δ) differs from J(0) by 1.6e-4 relative, so Gauss–Newton converges in 3
/// iterations (also for ±1 mm / ±1 mrad sets).
///
/// \par Rank
/// \f[ J = U S V^\top, \qquad s_0 \ge s_1 \ge \dots \ge s_{29}, \qquad
///     \rho = \#\{\, i : s_i > \mathrm{rank\_tolerance} \cdot s_0 \,\} \f]
/// by Eigen's JacobiSVD (two-sided Jacobi after a column-pivoting Householder QR to 30 × 30;
/// J. Demmel, K. Veselić, "Jacobi's method is more accurate than QR", SIAM J. Matrix Anal. Appl.
/// 13(4), 1992): backward stable, its floor ~1e-16·s_0 far below the finite-difference floor.
/// Measured on the 15 × 15 grid (at OPT table 2; the same to 3 digits at the nominal machine):
/// s_0 = 5.47e-2 m/unit; s_i/s_0 = 0.99, 0.10, 8.0e-2, 3.8e-2, 2.8e-2, 1.1e-2, 9.1e-3, 5.6e-3,
/// 2.4e-3, 2.2e-3, 1.3e-3, 1.3e-4, 8.6e-5, 4.7e-5, 3.5e-5 for i = 1..15; then 1.5e-7, 7.6e-8,
/// 2.6e-8, 2.7e-9 (four near-null directions); then ≤ 2.1e-11 (ten exact null directions, at the
/// finite-difference floor). With the default tolerance 1e-6 the rank is 16 (clear gap:
/// 3.5e-5 → 1.5e-7), 14 combinations are not identifiable.
///
/// \par The null space, and why
/// Exact (spots unchanged to ≤ 2e-11 m at 0.1 mm | mrad, measured; test_calibration.cpp asserts
/// < 1e-10 m; signs follow the defect frames of defect_catalog.hpp):
///  * 3 rigid translations of the head against the work plane. Spots are measured in the plane
///    frame, so moving the plane by t is moving everything else by −t; the source slides along
///    its own beam and a galvo along its own axis for free (no such defect exists):
///    x: work_plane.x + axis_x.y;  y: work_plane.y + source.y − axis_x.z + axis_y.z;
///    z: work_plane.z + source.z − axis_y.y (equal coefficients).
///  * 3 rigid rotations of the head against the plane (work_plane.a, b, c against source, axis
///    rotations, lever-arm translations and, for a and b, window tilts).
///  * 2 joint offsets: axis.a turns the rotor (an offset of the galvo angle); mirror.b turns the
///    mirror about its own axis parallel to the rotor axis, e_m away: the two differ by a slide of
///    the mirror in its own plane (invisible) and an \f$e_m \alpha^2/2\f$ change of offset
///    (1e-11 m at 0.1 mrad): axis_x.a − mirror_x.b and axis_y.a − mirror_y.b.
///  * 2 window differences: a parallel plate moves the ray by a vector that depends on the ray
///    direction, the plate normal and its thickness only, not on where the plate is; both windows
///    have the same thickness and the ray crosses both with the same direction, so tilting one by
///    +ε and the other by −ε cancels: window_1.a − window_2.a and window_1.b − window_2.b.
///
/// Near-null (below the tolerance: each changes spots by ≲ 1 nm per mm | mrad beyond what other
/// defects can absorb):
///  * 2 common window tilts: a tilt ε moves the ray by
///    \f$ \approx e_v (1 - n_1/n_2)\,\varepsilon \approx 0.93\ \mu\mathrm{m\ per\ mrad} \f$,
///    almost uniformly over the field, i.e. like a work-plane translation (so the windows are
///    listed alone, "1.00 window_1.a": their work-plane partners are ~1e-3);
///  * source.c = ε with source.y = −0.1 mm/mrad·ε acts as axis_x.a = ε/2: turning the incoming
///    beam about the vertical line through its hit point on mirror X (0.1 m downstream) turns the
///    reflected beam as a galvo X offset of half the angle would (the rotor axis is \f$e_m/\sqrt{2}\f$
///    from the hit point: not exact);
///  * axis_x.b = β acts as axis_y.a = −β/2: tilting galvo X about base x (the incoming beam
///    direction) turns the beam between the mirrors about base x, which is galvo Y's axis.
///
/// The list (CalibrationResult::null_space) is one basis of that space: the reduced row echelon
/// form of the null vectors, pivots taken from the last defect backwards (work plane, windows,
/// mirror Y, ...), each vector normalised, coefficients ≥ 0.01 printed with 2 decimals (0.01
/// rather than 0.1: the 0.09 source.y lever arm of the source.c line matters; equal printed
/// coefficients in table order). Measured (15 × 15 fieldAngleGrid, OPT table 2):
/// \verbatim
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
/// \endverbatim
/// (the rotations pick up the joint offsets and window tilts through the other pivots).
/// Identifiable: 16 combinations; on their own only mirror_x.z, mirror_x.a, mirror_y.z,
/// mirror_y.a (less than 1 % of their unit vector in the null space: 0.15 % for the offsets z,
/// ≤ 0.013 % for the tilts a), and those four only weakly (their directions carry the smallest
/// identifiable singular values, s/s_0 ~ 1e-4: a mirror offset looks like a translation of its
/// axis along the normal except for a (1 − cos q) term).
///
/// \par Levenberg–Marquardt restricted to the identifiable subspace
/// With \f$N\f$ the 30 − ρ null vectors (the last columns of V):
/// \f[ \Delta\delta = -\sum_{i<\rho} v_i\,\frac{s_i}{s_i^2 + \lambda}\,u_i^\top r
///     \;-\; N N^\top \delta \f]
/// The first term is the damped truncated-SVD (pseudo-inverse) step; the second pulls δ along the
/// null space toward the origin (it changes no spot to first order), so the iteration converges
/// to the minimum-norm point of the set of equivalent machines (the classical minimum-norm
/// Gauss–Newton iteration \f$\delta \leftarrow J^+(J\delta - r)\f$). λ starts at
/// \f$10^{-10} s_0^2\f$, ÷10 on an accepted step (cost not increased; not below
/// \f$10^{-16} s_0^2\f$), ×10 on a rejected one (give up, not converged, above
/// \f$10^{10} s_0^2\f$). J is re-evaluated after every accepted step. Stop (converged) when
/// \f[ \|U_\rho^\top r\| \le \max\left(10^{-6}\,\|r\|,\; 1\ \mathrm{pm}\cdot\sqrt{N}\right) \f]
/// (the spot change the Gauss–Newton step would make, i.e. the gradient in the data metric), or
/// when the accepted step is ≤ 1e-9 mm | mrad in every value; at most max_iterations steps. At
/// the end \f$\delta \mathrel{-}= N N^\top \delta\f$ at the final J (the estimate has no
/// null-space component there) and the residuals are recomputed.
///
/// \par Uncertainties
/// At the final J, with σ = CalibrationOptions::noise_m:
/// \f[ \mathrm{Cov} = \sigma^2 (J^\top J)^+ = \sigma^2 \sum_{i<\rho} \frac{v_i v_i^\top}{s_i^2} \f]
/// std_dev[i] = \f$\sqrt{\mathrm{Cov}_{ii}}\f$ when defect i is identifiable on its own
/// (‖row i of N‖ ≤ 0.01), else 0: the value of an entangled defect is the minimum-norm estimate,
/// meaningless alone (only the identifiable combinations are determined; its diagonal would be the
/// spread of that minimum-norm estimate). With noise_m = 0 every std_dev is 0.
///
/// \par Residuals
/// Over the spots, |r_k| the 2-D distance:
/// \f[ \mathrm{rms} = \sqrt{\frac{1}{N}\sum_k |r_k|^2}, \qquad \mathrm{max} = \max_k |r_k| \f]
/// so for pure Gaussian noise σ per axis the RMS is \f$\approx \sigma\sqrt{2}\sqrt{1 - \rho/2N}\f$.
///
/// \par Measured
/// g++ -O2, urdf/scanhead.urdf, default OpticsConfig, 15 × 15 fieldAngleGrid (θ_max = 0.1195,
/// 0.1228 rad), 65 × 65 bicubic tables built on the nominal / estimated model and measured on the
/// true machine with 41 × 41 probes over ±175 mm:
///  * OPT table 2, no noise: 3 iterations, 15 ms; fit residual RMS 2.6e-11 m, max 1.0e-10 m (the
///    near-null part of the truth left unmodelled); table error 264 µm → 0.0001 µm.
///  * randomDefectSet(seed, 0.1, 0.1), 1 µm noise (noise seed = seed + 1000): residual RMS
///    1.29–1.48 µm; table error max, uncorrected → corrected [µm]: seed 1: 214 → 0.51;
///    2: 127 → 0.58; 3: 357 → 0.41; 4: 130 → 0.90; 5: 235 → 0.68; 6: 202 → 0.56; 7: 398 → 0.38;
///    8: 172 → 0.64; 9: 390 → 0.60; 10: 369 → 0.88. Each calibration: 3 iterations, ~20 ms.
///  * Same, other conditions (seeds 1–3): ±0.5 or ±1 mm|mrad sets (up to 3.6 mm uncorrected):
///    0.41–0.58 µm; 7 × 7 grid: 1.0–1.5 µm; 5 × 5 grid: 1.3–1.7 µm; 5 µm noise: 2.1–2.9 µm.
///  * 1σ (1 µm noise, seed 5): mirror_x.z 0.30 mm, mirror_x.a 0.41 mrad, mirror_y.z 0.11 mm,
///    mirror_y.a 0.15 mrad (the Monte-Carlo spread over 40 noise draws agrees within 5 %): the
///    individual values are poorly determined, the spots are not.
///  * Eigen's JacobiSVD in place of the former hand-written one-sided Jacobi SVD (Hestenes) moved
///    these results only in the last digits: over OPT table 2 and random seeds 1, 3, 5, with and
///    without 1 µm noise, the same rank, iterations and null space text; estimates by ≤ 4.6e-7
///    mm | mrad, 1σ by ≤ 1.8e-7 relative, identifiable singular values by ≤ 1.8e-7 relative,
///    corrected table error by ≤ 1.3e-13 m.
///
/// \par Output
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
/// \par Simulated measurements
/// simulateMeasurements draws from SplitMix64(seed) (random.hpp) two uniforms per spot,
/// u₁, u₂ ∈ (0, 1] (uniformOpenClosed: the top 53 bits + 1 ulp), and adds the Box–Muller pair
/// (G. E. P. Box, M. E. Muller, Ann. Math. Statist. 29(2), 1958)
/// \f[ (n_x, n_y) = \sigma \sqrt{-2 \ln u_1}\,(\cos 2\pi u_2,\; \sin 2\pi u_2) \f]
/// std::normal_distribution is not used because its algorithm is implementation-defined (libm
/// log/cos may still differ in the last bit between platforms).
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
std::vector<SpotMeasurement> simulateMeasurements(const OpticalModel& machine,
                                                  const std::vector<Eigen::Vector2d>& angles, double noise_m,
                                                  std::uint64_t seed);

struct CalibrationOptions
{
  int max_iterations = 50;
  double rank_tolerance = 1e-6;  ///< singular values below this × the largest are not identifiable
  double noise_m = 1e-6;         ///< measurement noise assumed for the uncertainties [m]
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
  double rms_residual_m = 0.0;  ///< fit residual over the measurements [m]
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
