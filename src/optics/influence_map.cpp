/// \file influence_map.cpp
/// \brief Influence of each assembly defect on the spot (SPEC §4, OPT eq. 7, Fig. 5 and 6). The
/// angle grid's θ_max, the influence and its measured values are documented in influence_map.hpp.
#include "scanhead/optics/influence_map.hpp"

#include <algorithm>
#include <sstream>

#include "scanhead/common/errors.hpp"
#include "scanhead/common/number_text.hpp"

namespace scanhead
{
namespace
{
std::string pairText(const Eigen::Vector2d& v, double scale)
{
  return "[" + fullPrecisionText(v.x() * scale) + ", " + fullPrecisionText(v.y() * scale) + "]";
}
}  // namespace

std::vector<Eigen::Vector2d> fieldAngleGrid(const OpticalModel& nominal, int grid)
{
  if (grid < 1)
    throw InputError("influence map: the grid must have at least 1 point per axis (got " + std::to_string(grid) + ")");
  const double h = nominal.config().field_half_width_m;
  Eigen::Vector2d theta_max = Eigen::Vector2d::Zero();
  const double boundary[8][2] = {{1, 1}, {1, -1}, {-1, 1}, {-1, -1}, {1, 0}, {-1, 0}, {0, 1}, {0, -1}};
  Eigen::Vector2d guess = Eigen::Vector2d::Zero();
  for (const auto& b : boundary)
  {
    const Eigen::Vector2d q = nominal.inverse(Eigen::Vector2d(b[0] * h, b[1] * h), guess);
    theta_max = theta_max.cwiseMax(q.cwiseAbs());
  }
  std::vector<Eigen::Vector2d> angles;
  angles.reserve(static_cast<std::size_t>(grid) * static_cast<std::size_t>(grid));
  const double span = grid > 1 ? grid - 1 : 1;
  for (int j = 0; j < grid; ++j)
  {
    const double v = grid > 1 ? (2.0 * j - (grid - 1)) / span : 0.0;
    for (int i = 0; i < grid; ++i)
    {
      const double u = grid > 1 ? (2.0 * i - (grid - 1)) / span : 0.0;
      angles.emplace_back(u * theta_max.x(), v * theta_max.y());
    }
  }
  return angles;
}

std::vector<InfluenceRow> influenceTable(const OpticalGeometry& nominal, const OpticsConfig& config, int grid)
{
  const OpticalModel model(nominal, config);
  const std::vector<Eigen::Vector2d> angles = fieldAngleGrid(model, grid);
  std::vector<Eigen::Vector2d> spots;
  spots.reserve(angles.size());
  for (const Eigen::Vector2d& q : angles)
    spots.push_back(model.spot(q));
  const Eigen::Vector2d centre = model.spot(Eigen::Vector2d::Zero());

  std::vector<InfluenceRow> rows;
  rows.reserve(kDefectCount);
  for (std::size_t k = 0; k < kDefectCount; ++k)
  {
    DefectSet set;
    set.name = defectLabel(k);
    set.values[k] = 1.0;  // 1 mm or 1 mrad
    const OpticalModel defective(applyDefects(nominal, set), config);
    InfluenceRow row;
    row.defect = k;
    row.unit = set.values[k];
    row.shift_m = defective.spot(Eigen::Vector2d::Zero()) - centre;
    row.max_m = row.shift_m.norm();
    for (std::size_t p = 0; p < angles.size(); ++p)
    {
      const Eigen::Vector2d influence = defective.spot(angles[p]) - spots[p];
      const Eigen::Vector2d rest = influence - row.shift_m;
      row.nonlinear_min_m = row.nonlinear_min_m.cwiseMin(rest);
      row.nonlinear_max_m = row.nonlinear_max_m.cwiseMax(rest);
      row.nonlinear_m = std::max(row.nonlinear_m, rest.norm());
      row.max_m = std::max(row.max_m, influence.norm());
    }
    rows.push_back(row);
  }
  return rows;
}

DefectField defectField(const OpticalGeometry& nominal, const OpticsConfig& config, const DefectSet& set, int grid)
{
  const OpticalModel model(nominal, config);
  const OpticalModel defective(applyDefects(nominal, set), config);
  DefectField field;
  field.grid = grid;
  field.angles_rad = fieldAngleGrid(model, grid);
  field.nominal_spot_m.reserve(field.angles_rad.size());
  field.displacement_m.reserve(field.angles_rad.size());
  for (const Eigen::Vector2d& q : field.angles_rad)
  {
    const Eigen::Vector2d h = model.spot(q);
    field.nominal_spot_m.push_back(h);
    field.displacement_m.push_back(defective.spot(q) - h);
  }
  return field;
}

std::string influenceYaml(const std::vector<InfluenceRow>& rows)
{
  std::ostringstream out;
  out << "# scanhead influence of each assembly defect alone (SPEC §4, OPT eq. 7 and Fig. 5)\n"
         "# I(theta) = h_defect(theta) - h(theta) over the field; shift = I(0) [mm] (x, y);\n"
         "# nonlinear = I - I(0): per-axis min and max [um] (x, y), largest norm [um]; max = largest |I| [mm]\n"
         "defects:\n";
  for (const InfluenceRow& row : rows)
  {
    const bool rotation = row.defect < kDefectCount && defectComponents()[row.defect].rotation();
    out << "  - label: " << defectLabel(row.defect) << "\n"
        << "    unit: " << fullPrecisionText(row.unit) << (rotation ? " mrad" : " mm") << "\n"
        << "    shift_mm: " << pairText(row.shift_m, 1e3) << "\n"
        << "    nonlinear_min_um: " << pairText(row.nonlinear_min_m, 1e6) << "\n"
        << "    nonlinear_max_um: " << pairText(row.nonlinear_max_m, 1e6) << "\n"
        << "    nonlinear_um: " << fullPrecisionText(row.nonlinear_m * 1e6) << "\n"
        << "    max_mm: " << fullPrecisionText(row.max_m * 1e3) << "\n";
  }
  return out.str();
}

std::string defectFieldCsv(const DefectField& field)
{
  std::string out = "theta_x_rad,theta_y_rad,x_m,y_m,dx_m,dy_m\n";
  for (std::size_t p = 0; p < field.angles_rad.size(); ++p)
  {
    const Eigen::Vector2d& q = field.angles_rad[p];
    const Eigen::Vector2d& h = field.nominal_spot_m[p];
    const Eigen::Vector2d& d = field.displacement_m[p];
    out += fullPrecisionText(q.x()) + "," + fullPrecisionText(q.y()) + "," + fullPrecisionText(h.x()) + "," +
           fullPrecisionText(h.y()) + "," + fullPrecisionText(d.x()) + "," + fullPrecisionText(d.y()) + "\n";
  }
  return out;
}
}  // namespace scanhead
