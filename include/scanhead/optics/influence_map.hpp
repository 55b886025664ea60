/// \file influence_map.hpp
/// \brief How much each assembly defect moves the spot over the field (SPEC §4, OPT §4, Fig. 5
/// and 6): influence I_δ(θx, θy) = h_δ(θx, θy) − h(θx, θy) of a unit defect, split into the
/// global shift at O_p (θ = 0) and the non-linear remainder.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "scanhead/optics/defect_catalog.hpp"
#include "scanhead/optics/optical_model.hpp"

namespace scanhead
{
/// \brief The commanded angles the maps are evaluated on: a grid × grid square of (θx, θy)
/// covering the field: ±θ_max per axis from the nominal inverse of the field's corners and edge
/// midpoints (the pincushion makes the corners alone stop short of the edges on the axes).
///
/// \details \f[ \theta_i = \theta_{max,x} \frac{2i - (n - 1)}{n - 1} \f] likewise \f$\theta_j\f$,
/// stored j outer (θy), i inner (θx): index j·n + i; an odd n puts θ = 0 exactly in the middle.
/// \f$\theta_{max}\f$ per axis is the largest |θ| of the nominal inverse of the field's 4 corners
/// AND 4 edge midpoints: the pincushion makes
/// \f$x \approx (K_1 + K_2/\cos 2\theta_y) \tan 2\theta_x\f$ (closedFormSpot,
/// nominal_closed_form.hpp), so the corners need a smaller θx (0.1162 rad) than the middle of the
/// x edges (0.1195 rad): from the corners alone the square of angles would stop ~5 mm short of
/// x = ±175 mm at y = 0. Our nominal field: \f$\theta_{max}\f$ = 0.1195 rad in x, 0.1228 rad in y;
/// the square's corners then reach x = ±180.2 mm, beyond the field.
/// \param[in] grid n >= 1 points per axis
/// \throws InputError if \p grid < 1
std::vector<Eigen::Vector2d> fieldAngleGrid(const OpticalModel& nominal, int grid);

struct InfluenceRow
{
  std::size_t defect = 0;                                     ///< index in defectComponents()
  double unit = 1.0;                                          ///< the defect's value: 1 mm or 1 mrad
  Eigen::Vector2d shift_m = Eigen::Vector2d::Zero();          ///< I at θ = 0 (the global shift) [m]
  Eigen::Vector2d nonlinear_min_m = Eigen::Vector2d::Zero();  ///< min over the field of I − I(0), per axis [m]
  Eigen::Vector2d nonlinear_max_m = Eigen::Vector2d::Zero();  ///< max over the field of I − I(0), per axis [m]
  double nonlinear_m = 0.0;                                   ///< max over the field of |I − I(0)| [m]
  double max_m = 0.0;                                         ///< max over the field of |I| [m]
};

/// \brief One row per defect (OPT table order), each defect alone at 1 mm or 1 mrad, on the
/// fieldAngleGrid(grid) of the nominal machine.
///
/// \details Influence of defect \f$\delta_k\f$ (OPT eq. 7):
/// \f[ I(\theta) = h_\delta(\theta) - h(\theta) \f]
/// with \f$\delta_k\f$ = 1 (mm or mrad) and the 29 others 0, both models traced
/// (OpticalModel::trace), so nothing is linearised. Global shift I(0); non-linear part
/// I(θ) − I(0), whose per-axis min/max and largest norm are over the grid and θ = 0 (so
/// min ≤ 0 ≤ max always); max |I| likewise.
///
/// \par Measured
/// (urdf/scanhead.urdf, default OpticsConfig, grid 21; test_influence_map.cpp asserts these, see
/// the report there):
/// - source.y 1 mm: shift (+1.000, 0) mm, non-linear 0–29 µm (OPT Fig. 4: ≈ 1 mm, 0–0.12 mm)
/// - window rotations 1 mrad: max |I| = 1.07 µm, 1/895 of the median of the other rotations
///   (0.96 mm)
/// - rotations: the least of the source/head ones 0.76 mm, the most of the work plane's 0.25 mm
/// - opt_table2 set: max displacement 265.5 µm, (111.9, 155.9) µm at the centre
///
/// Cost: 31 models × 441 traces ≈ 14k traces, ~1 ms.
std::vector<InfluenceRow> influenceTable(const OpticalGeometry& nominal, const OpticsConfig& config, int grid = 21);

/// \brief The spot displacement a whole defect set causes over the field (OPT Fig. 6).
struct DefectField
{
  std::vector<Eigen::Vector2d> angles_rad;      ///< fieldAngleGrid
  std::vector<Eigen::Vector2d> nominal_spot_m;  ///< h(θ) of the nominal machine
  std::vector<Eigen::Vector2d> displacement_m;  ///< h_δ(θ) − h(θ)
  int grid = 0;
};
DefectField defectField(const OpticalGeometry& nominal, const OpticsConfig& config, const DefectSet& set,
                        int grid = 21);

/// \brief The table as YAML (mm and µm at the user edge: `label`, `unit`, `shift_mm`,
/// `nonlinear_min_um`, `nonlinear_max_um`, `nonlinear_um`, `max_mm`).
std::string influenceYaml(const std::vector<InfluenceRow>& rows);
/// \brief The field as CSV: theta_x_rad, theta_y_rad, x_m, y_m, dx_m, dy_m.
std::string defectFieldCsv(const DefectField& field);
}  // namespace scanhead
