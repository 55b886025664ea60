/// \file test_influence_map.cpp
/// \brief Influence of each assembly defect (SPEC §4, OPT §4): the field grid, OPT's reference
/// observations, known exact cases, superposition for the OPT table 2 machine, the writers.
#include <gtest/gtest.h>

#include <yaml-cpp/yaml.h>
#include <algorithm>
#include <cmath>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "fixtures/optics_fixture.hpp"
#include "scanhead/common/errors.hpp"
#include "scanhead/optics/influence_map.hpp"

#ifndef SCANHEAD_SOURCE_DIR
#error "SCANHEAD_SOURCE_DIR (repository root) must be defined"
#endif

namespace scanhead
{
namespace
{
const std::string& kUrdfPath = test_support::kNominalUrdfPath;

const OpticalGeometry& nominal()
{
  return test_support::nominalGeometry();
}

const std::vector<InfluenceRow>& table()
{
  static const std::vector<InfluenceRow> rows = influenceTable(nominal(), OpticsConfig(), 21);
  return rows;
}

const InfluenceRow& row(const std::string& label)
{
  return table()[defectIndex(label)];
}

bool isElement(std::size_t k, const std::string& element)
{
  return std::string(defectComponents()[k].element) == element;
}

bool isWorkPlane(std::size_t k)
{
  return isElement(k, "work_plane");
}

bool isWindow(std::size_t k)
{
  return isElement(k, "window_1") || isElement(k, "window_2");
}

TEST(InfluenceMap, FieldAngleGridCoversTheField)
{
  const OpticsConfig config;
  const OpticalModel model(nominal(), config);
  const int n = 21;
  const std::vector<Eigen::Vector2d> angles = fieldAngleGrid(model, n);
  ASSERT_EQ(angles.size(), static_cast<std::size_t>(n * n));
  const double h = config.field_half_width_m;
  // Odd grid: θ = 0 exactly in the middle; θx runs fastest; the square is symmetric.
  EXPECT_EQ(angles[(n * n) / 2], Eigen::Vector2d::Zero());
  EXPECT_LT(angles[0].x(), angles[1].x());
  EXPECT_EQ(angles[0].y(), angles[1].y());
  EXPECT_EQ(angles[0], -angles[n * n - 1]);
  // The square contains the inverse of every point of the field (41 × 41 points, borders
  // included; 1e-12 rad: the Newton tolerance is 1e-12 m, ~1e-12 rad), and it is no bigger than
  // needed: some field point needs θ_max on each axis (within 1e-9 rad).
  const Eigen::Vector2d theta_max = angles.back();
  Eigen::Vector2d needed = Eigen::Vector2d::Zero();
  const int m = 41;
  for (int j = 0; j < m; ++j)
  {
    for (int i = 0; i < m; ++i)
    {
      const Eigen::Vector2d spot(h * (2.0 * i / (m - 1) - 1.0), h * (2.0 * j / (m - 1) - 1.0));
      needed = needed.cwiseMax(model.inverse(spot).cwiseAbs());
    }
  }
  EXPECT_LE(needed.x(), theta_max.x() + 1e-12);
  EXPECT_LE(needed.y(), theta_max.y() + 1e-12);
  EXPECT_NEAR(needed.x(), theta_max.x(), 1e-9);
  EXPECT_NEAR(needed.y(), theta_max.y(), 1e-9);
  // From the corners alone θ_max,x would be too small (pincushion: the x edge's middle needs more).
  EXPECT_GT(theta_max.x(), std::abs(model.inverse(Eigen::Vector2d(h, h)).x()) + 1e-3);
  std::cout << "[ measured ] theta_max = (" << angles.back().x() << ", " << angles.back().y() << ") rad\n";

  EXPECT_EQ(fieldAngleGrid(model, 1), std::vector<Eigen::Vector2d>(1, Eigen::Vector2d::Zero()));
  EXPECT_THROW(fieldAngleGrid(model, 0), InputError);
}

TEST(InfluenceMap, ZeroDefectGivesZeroInfluence)
{
  // A defect of 0 leaves the geometry bit for bit, so I = 0 exactly (no tolerance).
  DefectSet zero;
  zero.values[defectIndex("mirror_x.a")] = 0.0;
  zero.values[defectIndex("source.y")] = -0.0;
  for (const DefectSet& set : {DefectSet(), zero})
  {
    const DefectField field = defectField(nominal(), OpticsConfig(), set, 11);
    ASSERT_EQ(field.displacement_m.size(), 121u);
    for (const Eigen::Vector2d& d : field.displacement_m)
    {
      EXPECT_EQ(d.x(), 0.0);
      EXPECT_EQ(d.y(), 0.0);
    }
  }
}

TEST(InfluenceMap, TableRowsAreConsistent)
{
  ASSERT_EQ(table().size(), kDefectCount);
  for (std::size_t k = 0; k < kDefectCount; ++k)
  {
    const InfluenceRow& r = table()[k];
    EXPECT_EQ(r.defect, k);
    EXPECT_EQ(r.unit, 1.0);
    // min <= 0 <= max (θ = 0 belongs to the field), |rest| <= the norm of the per-axis bounds,
    // and |I| <= |I(0)| + max |I − I(0)| (triangle inequality); 1e-15 m for rounding.
    EXPECT_LE(r.nonlinear_min_m.maxCoeff(), 0.0);
    EXPECT_GE(r.nonlinear_max_m.minCoeff(), 0.0);
    const Eigen::Vector2d bound = r.nonlinear_min_m.cwiseAbs().cwiseMax(r.nonlinear_max_m.cwiseAbs());
    EXPECT_LE(r.nonlinear_m, bound.norm() + 1e-15);
    EXPECT_GE(r.nonlinear_m, bound.maxCoeff() - 1e-15);
    EXPECT_LE(r.max_m, r.shift_m.norm() + r.nonlinear_m + 1e-15);
    EXPECT_GE(r.max_m, r.shift_m.norm());
    EXPECT_GT(r.max_m, 0.0) << defectLabel(k) << " has no effect";
  }
}

TEST(InfluenceMap, SourceShiftMovesTheSpotByAboutOneMillimetre)
{
  // OPT §4.1, Fig. 4: δy_s = 1 mm moves the spot ≈ 1 mm everywhere, non-linear part 0–0.12 mm.
  // Our source.y moves the beam across mirror X, whose 45° reflection turns it into an x shift.
  const InfluenceRow& r = row("source.y");
  std::cout << "[ measured ] source.y 1 mm: shift (" << r.shift_m.x() * 1e3 << ", " << r.shift_m.y() * 1e3
            << ") mm, non-linear x " << r.nonlinear_min_m.x() * 1e3 << " .. " << r.nonlinear_max_m.x() * 1e3
            << " mm, y " << r.nonlinear_min_m.y() * 1e3 << " .. " << r.nonlinear_max_m.y() * 1e3 << " mm, |.| max "
            << r.nonlinear_m * 1e3 << " mm\n";
  EXPECT_NEAR(std::abs(r.shift_m.x()), 1e-3, 0.2e-3);  // brief: ±20 % of 1 mm on the relevant axis
  EXPECT_LT(std::abs(r.shift_m.y()), 0.2e-3);
  EXPECT_GT(r.nonlinear_m, 0.01e-3);  // brief: "of order 0.1 mm", between 0.01 and 0.3 mm
  EXPECT_LT(r.nonlinear_m, 0.3e-3);
  // Theory: a plane mirror keeps the distance between parallel rays, so the beam leaves mirror Y
  // 1 mm beside the nominal one, and the spot moves by 1 mm / cos 2θx along x (the offset is
  // horizontal and perpendicular to the beam after mirror X): non-linear part at the field's
  // edge 1 mm·(1/cos 2θ_max − 1), θ_max from the grid. 1e-9 m: exact geometry, rounding only.
  const double theta_max = fieldAngleGrid(OpticalModel(nominal(), OpticsConfig()), 3).back().x();
  EXPECT_NEAR(r.nonlinear_max_m.x(), 1e-3 * (1.0 / std::cos(2.0 * theta_max) - 1.0), 1e-9);
}

TEST(InfluenceMap, WindowTiltsWeighAboutAThousandTimesLess)
{
  // OPT §4.2: window orientation defects are ~1000× less influential than the others.
  std::vector<double> others;
  double windows = 0.0;
  for (std::size_t k = 0; k < kDefectCount; ++k)
  {
    if (!defectComponents()[k].rotation())
      continue;
    if (isWindow(k))
      windows = std::max(windows, table()[k].max_m);
    else
      others.push_back(table()[k].max_m);
  }
  ASSERT_EQ(others.size(), 15u);  // 19 orientation defects, 4 of them the windows'
  std::sort(others.begin(), others.end());
  const double median = others[others.size() / 2];
  std::cout << "[ measured ] windows max |I| at 1 mrad " << windows * 1e6 << " um; other rotations median "
            << median * 1e3 << " mm; ratio 1/" << median / windows << "\n";
  EXPECT_LT(windows, median / 200.0);  // brief: < 1/200 of the median
  EXPECT_GT(windows, 0.0);
  // Theory: a plate of thickness e_v tilted by ε shifts a normal ray by e_v·ε·(1 − n1/n2)
  // (= 0.93 µm here); at θ = 0 that is the whole shift. 1e-11 m: the formula is first order in
  // ε = 1e-3 (relative error ~ε²).
  const OpticsConfig c;
  const double expected = c.window_thickness_m * 1e-3 * (1.0 - c.n_gas / c.n_window);
  for (const char* label : {"window_1.a", "window_1.b", "window_2.a", "window_2.b"})
  {
    EXPECT_NEAR(row(label).shift_m.norm(), expected, 1e-11) << label;
  }
}

TEST(InfluenceMap, HeadDefectsWeighMoreThanWorkPlaneDefects)
{
  // OPT §4.2: the defects of the source and the scan head (axes, mirrors) weigh more than those of
  // the work plane. Measured as max |I| over the field per unit defect.
  double head_rot_min = 1.0;
  double plane_rot_max = 0.0;
  double head_trans_min = 1.0;
  double head_trans_sum = 0.0;
  int head_trans_count = 0;
  double plane_trans_max = 0.0;
  for (std::size_t k = 0; k < kDefectCount; ++k)
  {
    if (isWindow(k))
      continue;
    const double m = table()[k].max_m;
    const bool rotation = defectComponents()[k].rotation();
    if (isWorkPlane(k))
    {
      (rotation ? plane_rot_max : plane_trans_max) = std::max(rotation ? plane_rot_max : plane_trans_max, m);
    }
    else if (rotation)
    {
      head_rot_min = std::min(head_rot_min, m);
    }
    else
    {
      head_trans_min = std::min(head_trans_min, m);
      head_trans_sum += m;
      ++head_trans_count;
    }
  }
  ASSERT_EQ(head_trans_count, 8);
  const double head_trans_mean = head_trans_sum / head_trans_count;
  std::cout << "[ measured ] rotations, 1 mrad: head min " << head_rot_min * 1e3 << " mm, work plane max "
            << plane_rot_max * 1e3 << " mm; translations, 1 mm: head min " << head_trans_min * 1e3 << " mm, mean "
            << head_trans_mean * 1e3 << " mm, work plane max " << plane_trans_max * 1e3 << " mm\n";
  // Rotations: every source/head rotation weighs more than every work-plane rotation (by ≥ 2×:
  // a tilted mirror turns the beam by 2 mrad over ~0.7 m, a tilted plane only moves the spot by
  // its distance from the tilt axis × ~tan of the beam angle, or × 1 mrad for a turn about z).
  EXPECT_GT(head_rot_min, 2.0 * plane_rot_max);
  // Translations: a work-plane translation in x or y moves the spot by exactly 1 mm everywhere,
  // a pure offset (no non-linear part) that recalibrating the origin O_p removes; along z it moves
  // it by 0 at the centre. So "weigh more" can only mean: no head translation moves the spot less
  // (the least, axis_x.y, is also exactly 1 mm: it slides mirror X along the beam), and on average
  // they move it more (reflection doubling, √2 for a mirror moved along its normal), plus a
  // non-linear part. 1e-12 m: rounding.
  EXPECT_GE(head_trans_min, plane_trans_max - 1e-12);
  EXPECT_GT(head_trans_mean, 1.1 * plane_trans_max);
  for (const char* label : {"work_plane.x", "work_plane.y"})
  {
    EXPECT_NEAR(row(label).max_m, 1e-3, 1e-12) << label;
    EXPECT_LT(row(label).nonlinear_m, 1e-12) << label;
  }
  EXPECT_NEAR(row("work_plane.x").shift_m.x(), -1e-3, 1e-12);  // the plane moves, the spot in it moves back
  EXPECT_NEAR(row("work_plane.y").shift_m.y(), -1e-3, 1e-12);
}

TEST(InfluenceMap, KnownExactInfluences)
{
  const OpticsConfig config;
  const OpticalModel model(nominal(), config);
  // A mirror moved by δ along its normal shifts the reflected beam by 2δ·cos i (i = 45° at θ = 0):
  // √2 mm for 1 mm, across the beam. 1e-9 m: exact geometry, rounding only.
  EXPECT_NEAR(row("mirror_x.z").shift_m.norm(), std::sqrt(2.0) * 1e-3, 1e-9);
  EXPECT_NEAR(row("mirror_y.z").shift_m.norm(), std::sqrt(2.0) * 1e-3, 1e-9);
  // Work plane raised by δ = 1 mm: the straight ray below the windows meets it earlier,
  // I(θ) = δ·d_h/d_z (d = beam direction at the plane), exact for a translation along the normal.
  DefectSet raised;
  raised.values[defectIndex("work_plane.z")] = 1.0;
  const DefectField field = defectField(nominal(), config, raised, 9);
  double worst = 0.0;
  for (std::size_t p = 0; p < field.angles_rad.size(); ++p)
  {
    const Eigen::Vector3d d = model.trace(field.angles_rad[p]).direction;
    worst = std::max(worst, (field.displacement_m[p] - 1e-3 * d.head<2>() / d.z()).norm());
  }
  EXPECT_LT(worst, 1e-12);
  EXPECT_GT(row("work_plane.z").max_m, 0.3e-3);  // ~0.355 mm at the corners (r/H ≈ 0.25/0.7)
}

TEST(InfluenceMap, OptTable2FieldIsTheSumOfTheUnitInfluences)
{
  // OPT Fig. 6: the OPT table 2 machine. To first order its displacement is Σ δ_k I_k(θ); the
  // neglected terms are products of two defects of ≤ 0.1 mm/mrad with the second derivatives of
  // h (~1 m/rad²): ~1e-8 m each, hence the 0.5 µm tolerance.
  const OpticsConfig config;
  const DefectSet set = optTable2DefectSet();
  const int n = 11;
  const DefectField field = defectField(nominal(), config, set, n);
  ASSERT_EQ(field.grid, n);
  ASSERT_EQ(field.displacement_m.size(), static_cast<std::size_t>(n * n));
  std::vector<Eigen::Vector2d> sum(field.displacement_m.size(), Eigen::Vector2d::Zero());
  double linear_bound = 0.0;
  for (std::size_t k = 0; k < kDefectCount; ++k)
  {
    DefectSet unit;
    unit.values[k] = 1.0;
    const DefectField one = defectField(nominal(), config, unit, n);
    for (std::size_t p = 0; p < sum.size(); ++p)
      sum[p] += set.values[k] * one.displacement_m[p];
    linear_bound += std::abs(set.values[k]) * table()[k].max_m;
  }
  double worst = 0.0;
  double largest = 0.0;
  for (std::size_t p = 0; p < sum.size(); ++p)
  {
    worst = std::max(worst, (field.displacement_m[p] - sum[p]).norm());
    largest = std::max(largest, field.displacement_m[p].norm());
  }
  const Eigen::Vector2d centre = field.displacement_m[sum.size() / 2];
  std::cout << "[ measured ] opt_table2: max displacement " << largest * 1e6 << " um, centre (" << centre.x() * 1e6
            << ", " << centre.y() * 1e6 << ") um; |field - superposition| max " << worst * 1e6
            << " um; first-order bound " << linear_bound * 1e6 << " um\n";
  EXPECT_LT(worst, 0.5e-6);
  // Plausible: 30 defects of ≤ 0.1 mm/mrad, each ~1 mm per unit, partly cancelling; at most the
  // first-order bound Σ|δ_k|·max|I_k| (+1 % for the second-order terms), and not small.
  EXPECT_LT(largest, 1.01 * linear_bound);
  EXPECT_GT(largest, 100e-6);
  EXPECT_EQ(field.angles_rad, fieldAngleGrid(OpticalModel(nominal(), config), n));
  EXPECT_EQ(field.nominal_spot_m[0], OpticalModel(nominal(), config).spot(field.angles_rad[0]));
}

TEST(InfluenceMap, WritersParseBack)
{
  const YAML::Node doc = YAML::Load(influenceYaml(table()));
  const YAML::Node rows = doc["defects"];
  ASSERT_TRUE(rows.IsSequence());
  ASSERT_EQ(rows.size(), kDefectCount);
  for (std::size_t k = 0; k < kDefectCount; ++k)
  {
    const YAML::Node r = rows[k];
    const InfluenceRow& t = table()[k];
    EXPECT_EQ(r["label"].as<std::string>(), defectLabel(k));
    EXPECT_EQ(r["unit"].as<std::string>(), defectComponents()[k].rotation() ? "1 mrad" : "1 mm");
    // 17 significant digits: the scaled numbers read back exactly.
    EXPECT_EQ(r["shift_mm"][0].as<double>(), t.shift_m.x() * 1e3);
    EXPECT_EQ(r["shift_mm"][1].as<double>(), t.shift_m.y() * 1e3);
    EXPECT_EQ(r["nonlinear_min_um"][1].as<double>(), t.nonlinear_min_m.y() * 1e6);
    EXPECT_EQ(r["nonlinear_max_um"][0].as<double>(), t.nonlinear_max_m.x() * 1e6);
    EXPECT_EQ(r["nonlinear_um"].as<double>(), t.nonlinear_m * 1e6);
    EXPECT_EQ(r["max_mm"].as<double>(), t.max_m * 1e3);
  }

  const int n = 5;
  const DefectField field = defectField(nominal(), OpticsConfig(), optTable2DefectSet(), n);
  std::istringstream csv(defectFieldCsv(field));
  std::string line;
  ASSERT_TRUE(std::getline(csv, line));
  EXPECT_EQ(line, "theta_x_rad,theta_y_rad,x_m,y_m,dx_m,dy_m");
  std::size_t count = 0;
  while (std::getline(csv, line))
  {
    std::istringstream fields(line);
    std::string cell;
    std::vector<double> values;
    while (std::getline(fields, cell, ','))
      values.push_back(std::stod(cell));
    ASSERT_EQ(values.size(), 6u) << line;
    ASSERT_LT(count, field.angles_rad.size());
    EXPECT_EQ(values[0], field.angles_rad[count].x());
    EXPECT_EQ(values[3], field.nominal_spot_m[count].y());
    EXPECT_EQ(values[4], field.displacement_m[count].x());
    ++count;
  }
  EXPECT_EQ(count, static_cast<std::size_t>(n * n));
}
}  // namespace
}  // namespace scanhead
