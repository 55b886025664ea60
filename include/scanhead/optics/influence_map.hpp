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
std::vector<Eigen::Vector2d> fieldAngleGrid(const OpticalModel& nominal, int grid);

struct InfluenceRow
{
  std::size_t defect = 0;                              ///< index in defectComponents()
  double unit = 1.0;                                   ///< the defect's value: 1 mm or 1 mrad
  Eigen::Vector2d shift_m = Eigen::Vector2d::Zero();   ///< I at θ = 0 (the global shift) [m]
  Eigen::Vector2d nonlinear_min_m = Eigen::Vector2d::Zero();  ///< min over the field of I − I(0), per axis [m]
  Eigen::Vector2d nonlinear_max_m = Eigen::Vector2d::Zero();  ///< max over the field of I − I(0), per axis [m]
  double nonlinear_m = 0.0;                            ///< max over the field of |I − I(0)| [m]
  double max_m = 0.0;                                  ///< max over the field of |I| [m]
};

/// \brief One row per defect (OPT table order), each defect alone at 1 mm or 1 mrad, on the
/// fieldAngleGrid(grid) of the nominal machine.
std::vector<InfluenceRow> influenceTable(const OpticalGeometry& nominal, const OpticsConfig& config, int grid = 21);

/// \brief The spot displacement a whole defect set causes over the field (OPT Fig. 6).
struct DefectField
{
  std::vector<Eigen::Vector2d> angles_rad;      ///< fieldAngleGrid
  std::vector<Eigen::Vector2d> nominal_spot_m;  ///< h(θ) of the nominal machine
  std::vector<Eigen::Vector2d> displacement_m;  ///< h_δ(θ) − h(θ)
  int grid = 0;
};
DefectField defectField(const OpticalGeometry& nominal, const OpticsConfig& config, const DefectSet& set, int grid = 21);

/// \brief The table as YAML (mm and µm at the user edge: `label`, `unit`, `shift_mm`,
/// `nonlinear_min_um`, `nonlinear_max_um`, `nonlinear_um`, `max_mm`).
std::string influenceYaml(const std::vector<InfluenceRow>& rows);
/// \brief The field as CSV: theta_x_rad, theta_y_rad, x_m, y_m, dx_m, dy_m.
std::string defectFieldCsv(const DefectField& field);
}  // namespace scanhead
