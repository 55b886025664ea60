/// \file test_optical_defects.cpp
/// \brief The 30 assembly defects (SPEC §4, OPT tables 1-2): the component table, its mapping onto
/// our defect joints (checked on the geometry), defect set files and their errors, random sets,
/// the defective URDF against applyDefects, and that each of the 30 is a real defect.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "fixtures/optics_fixture.hpp"
#include "scanhead/common/errors.hpp"
#include "scanhead/optics/optical_defects.hpp"

#ifndef SCANHEAD_SOURCE_DIR
#error "SCANHEAD_SOURCE_DIR (repository root) must be defined"
#endif

namespace scanhead
{
namespace
{
const std::string& kUrdfPath = test_support::kNominalUrdfPath;
const std::string kDefectsDir = std::string(SCANHEAD_SOURCE_DIR) + "/config/defects/";

std::string readFile(const std::string& path)
{
  std::ifstream in(path);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

const OpticalGeometry& nominal()
{
  return test_support::nominalGeometry();
}

std::array<const Eigen::Isometry3d*, 8> poses(const OpticalGeometry& g)
{
  return {&g.source, &g.mount_x, &g.mirror_x, &g.mount_y, &g.mirror_y, &g.window_1, &g.window_2, &g.work_plane};
}

Eigen::Isometry3d& pose(OpticalGeometry& g, std::size_t element)
{
  Eigen::Isometry3d* const p[8] = {&g.source,   &g.mount_x,  &g.mirror_x, &g.mount_y,
                                   &g.mirror_y, &g.window_1, &g.window_2, &g.work_plane};
  return *p[element];
}

/// Joint angles spread over the field (±0.12 rad ≈ ±170 mm).
std::vector<Eigen::Vector2d> fieldAngles()
{
  std::vector<Eigen::Vector2d> q;
  for (double a = -0.12; a <= 0.12 + 1e-9; a += 0.04)
    for (double b = -0.12; b <= 0.12 + 1e-9; b += 0.04)
      q.emplace_back(a, b);
  return q;
}

/// Largest spot difference [m] between two geometries over fieldAngles().
double maxSpotChange(const OpticalGeometry& a, const OpticalGeometry& b)
{
  const OpticalModel ma(a, OpticsConfig());
  const OpticalModel mb(b, OpticsConfig());
  double worst = 0.0;
  for (const Eigen::Vector2d& q : fieldAngles())
    worst = std::max(worst, (ma.spot(q) - mb.spot(q)).norm());
  return worst;
}

DefectSet single(std::size_t index, double value)
{
  DefectSet set;
  set.name = defectLabel(index);
  set.values[index] = value;
  return set;
}

std::string tempPath(const std::string& name)
{
  return (std::filesystem::temp_directory_path() / ("scanhead_test_optical_defects_" + name)).string();
}

bool sameBits(const DefectSet& a, const DefectSet& b)
{
  return std::memcmp(a.values.data(), b.values.data(), sizeof(double) * kDefectCount) == 0;
}

/// Angle [rad] between two unit vectors (atan2 form: accurate for small angles).
double angleBetween(const Eigen::Vector3d& a, const Eigen::Vector3d& b)
{
  return std::atan2(a.cross(b).norm(), a.dot(b));
}
}  // namespace

TEST(OpticalDefects, ComponentTableIsOptTable1InOrder)
{
  // OPT table 1 / SPEC §4, row by row.
  const char* const expected[kDefectCount] = {
      "source.y",     "source.z",     "source.b",     "source.c",     "axis_x.y",     "axis_x.z",
      "axis_x.a",     "axis_x.b",     "axis_x.c",     "mirror_x.z",   "mirror_x.a",   "mirror_x.b",
      "axis_y.y",     "axis_y.z",     "axis_y.a",     "axis_y.b",     "axis_y.c",     "mirror_y.z",
      "mirror_y.a",   "mirror_y.b",   "window_1.a",   "window_1.b",   "window_2.a",   "window_2.b",
      "work_plane.x", "work_plane.y", "work_plane.z", "work_plane.a", "work_plane.b", "work_plane.c",
  };
  ASSERT_EQ(defectComponents().size(), 30u);
  int rotations = 0;
  for (std::size_t k = 0; k < kDefectCount; ++k)
  {
    const DefectComponent& c = defectComponents()[k];
    EXPECT_EQ(defectLabel(k), expected[k]);
    EXPECT_EQ(std::string(c.element) + "." + c.component, expected[k]);
    EXPECT_EQ(c.rotation(), c.component == 'a' || c.component == 'b' || c.component == 'c');
    rotations += c.rotation() ? 1 : 0;
  }
  EXPECT_EQ(rotations, 19);  // 11 positions (mm), 19 orientations (mrad)
  const std::array<std::string, 8> joints = {"laser_source", "galvo_x_mount", "mirror_x", "galvo_y_mount",
                                             "mirror_y",     "window_1",      "window_2", "work_plane"};
  EXPECT_EQ(defectJointElements(), joints);
  EXPECT_THROW(defectLabel(30), std::out_of_range);
}

TEST(OpticalDefects, MappingPutsEachComponentOnItsJointAxis)
{
  // The table of defect_catalog.hpp, transcribed independently: OPT component → (our joint,
  // t = translation / r = rotation, our axis 0 1 2 = x y z or roll pitch yaw). 1 mm / 1 mrad must
  // come out as exactly 1e-3 m / 1e-3 rad there and nothing elsewhere.
  struct Row
  {
    const char* label;
    std::size_t joint;
    char kind;
    int axis;
  };
  const Row rows[kDefectCount] = {
      {"source.y", 0, 't', 1},     {"source.z", 0, 't', 2},     {"source.b", 0, 'r', 1},
      {"source.c", 0, 'r', 2},     {"axis_x.y", 1, 't', 0},     {"axis_x.z", 1, 't', 1},
      {"axis_x.a", 1, 'r', 2},     {"axis_x.b", 1, 'r', 0},     {"axis_x.c", 1, 'r', 1},
      {"mirror_x.z", 2, 't', 0},   {"mirror_x.a", 2, 'r', 1},   {"mirror_x.b", 2, 'r', 2},
      {"axis_y.y", 3, 't', 0},     {"axis_y.z", 3, 't', 1},     {"axis_y.a", 3, 'r', 2},
      {"axis_y.b", 3, 'r', 0},     {"axis_y.c", 3, 'r', 1},     {"mirror_y.z", 4, 't', 0},
      {"mirror_y.a", 4, 'r', 1},   {"mirror_y.b", 4, 'r', 2},   {"window_1.a", 5, 'r', 0},
      {"window_1.b", 5, 'r', 1},   {"window_2.a", 6, 'r', 0},   {"window_2.b", 6, 'r', 1},
      {"work_plane.x", 7, 't', 0}, {"work_plane.y", 7, 't', 1}, {"work_plane.z", 7, 't', 2},
      {"work_plane.a", 7, 'r', 0}, {"work_plane.b", 7, 'r', 1}, {"work_plane.c", 7, 'r', 2},
  };
  for (const Row& row : rows)
  {
    const std::array<ElementDefect, 8> d = elementDefects(single(defectIndex(row.label), 1.0));
    for (std::size_t j = 0; j < 8; ++j)
    {
      for (int axis = 0; axis < 3; ++axis)
      {
        const bool here = j == row.joint && axis == row.axis;
        EXPECT_EQ(d[j].translation_m[axis], here && row.kind == 't' ? 1e-3 : 0.0) << row.label << " joint " << j;
        EXPECT_EQ(d[j].rotation_rad[axis], here && row.kind == 'r' ? 1e-3 : 0.0) << row.label << " joint " << j;
      }
    }
  }
}

TEST(OpticalDefects, MappingGivesEachComponentItsOptRole)
{
  // Geometry of the nominal frames, not bookkeeping: 1 mm / 1 mrad of each component moves the
  // defect frame (in scanhead_base) the way OPT's table 1 means it. OPT frames: source beam on x,
  // galvo rotation axis on x, normal of mirrors / windows / plane on z. Tolerances: 1e-15 m and
  // 1e-12 rad (rounding of 1e-3 against the frames' ~1 entries and ~0.7 m offsets).
  const OpticalModel nominal_model(nominal(), OpticsConfig());
  auto frame = [](const OpticalGeometry& g, std::size_t joint) {
    const OpticalModel m(g, OpticsConfig());
    if (joint == 2)
      return m.mirrorXPose(0.0);
    if (joint == 4)
      return m.mirrorYPose(0.0);
    return *poses(g)[joint];
  };
  const double tol_m = 1e-15;
  const double tol_rad = 1e-12;
  for (std::size_t k = 0; k < kDefectCount; ++k)
  {
    const DefectComponent& c = defectComponents()[k];
    const std::string element = c.element;
    const std::size_t joint = std::find(defectJointElements().begin(), defectJointElements().end(),
                                        element == "source"   ? "laser_source"
                                        : element == "axis_x" ? "galvo_x_mount"
                                        : element == "axis_y" ? "galvo_y_mount"
                                                              : element) -
                              defectJointElements().begin();
    ASSERT_LT(joint, 8u) << element;
    const Eigen::Isometry3d p0 = frame(nominal(), joint);
    const Eigen::Isometry3d p1 = frame(applyDefects(nominal(), single(k, 1.0)), joint);
    const Eigen::Vector3d moved = p1.translation() - p0.translation();
    // The OPT role axes of this element, in scanhead_base.
    const bool source = element == "source";
    const bool axis = element.rfind("axis_", 0) == 0;
    const Eigen::Vector3d beam = p0.linear().col(0);   // source: beam direction (OPT x)
    const Eigen::Vector3d rotor = p0.linear().col(2);  // galvo mount: rotation axis (OPT x)
    const Eigen::Vector3d normal = element.rfind("mirror_", 0) == 0 ? p0.linear().col(0)   // mirrors: normal (OPT z)
                                                                    : p0.linear().col(2);  // windows, plane
    const std::string what = defectLabel(k);
    if (!c.rotation())
    {
      EXPECT_NEAR(moved.norm(), 1e-3, tol_m) << what;
      EXPECT_EQ((p1.linear() - p0.linear()).cwiseAbs().maxCoeff(), 0.0) << what << ": a translation must not rotate";
      if (source)
        EXPECT_NEAR(moved.dot(beam), 0.0, tol_m) << what << ": across the beam";
      else if (axis)
        EXPECT_NEAR(moved.dot(rotor), 0.0, tol_m) << what << ": across the rotation axis";
      else if (c.component == 'z')
        EXPECT_NEAR(std::abs(moved.dot(normal)), 1e-3, tol_m) << what << ": along the normal";
      else
        EXPECT_NEAR(moved.dot(normal), 0.0, tol_m) << what << ": in the plane";
      continue;
    }
    EXPECT_LT(moved.norm(), tol_m) << what << ": a rotation about the frame origin does not move it";
    const Eigen::AngleAxisd turn(p0.linear().transpose() * p1.linear());
    EXPECT_NEAR(turn.angle(), 1e-3, tol_rad) << what;
    if (source)
      EXPECT_NEAR(angleBetween(beam, p1.linear().col(0)), 1e-3, tol_rad) << what << ": the beam turns";
    else if (axis && c.component == 'a')
      EXPECT_LT(angleBetween(rotor, p1.linear().col(2)), tol_rad) << what << ": about the rotation axis";
    else if (axis)
      EXPECT_NEAR(angleBetween(rotor, p1.linear().col(2)), 1e-3, tol_rad) << what << ": the axis tilts";
    else if (c.component == 'c')
      EXPECT_LT(angleBetween(normal, p1.linear().col(2)), tol_rad) << what << ": about the plane normal";
    else
    {
      const Eigen::Vector3d normal1 = element.rfind("mirror_", 0) == 0 ? p1.linear().col(0) : p1.linear().col(2);
      EXPECT_NEAR(angleBetween(normal, normal1), 1e-3, tol_rad) << what << ": the normal tilts";
    }
  }
}

TEST(OpticalDefects, TheOther18MotionsDoNothing)
{
  // 8 frames × 6 motions = 48 = the 30 defects + 18 motions that keep every surface (or the beam)
  // where it is: source along / about its beam, a galvo mount along its axis, a mirror in its
  // plane and about its normal, a window in its plane, along its normal, about its normal. Each
  // of the 18 axes no OPT component maps to is applied directly (1 mm / 10 mrad) to the nominal
  // frame and must leave every spot within 1e-12 m (rounding of ~0.2 m numbers).
  int null_motions = 0;
  for (std::size_t joint = 0; joint < 8; ++joint)
  {
    for (int kind = 0; kind < 2; ++kind)
    {
      for (int axis = 0; axis < 3; ++axis)
      {
        bool mapped = false;
        for (std::size_t k = 0; k < kDefectCount; ++k)
        {
          const ElementDefect d = elementDefects(single(k, 1.0))[joint];
          mapped = mapped || (kind == 0 ? d.translation_m[axis] : d.rotation_rad[axis]) != 0.0;
        }
        if (mapped || joint == 7)  // the work plane has all six
          continue;
        ++null_motions;
        OpticalGeometry g = nominal();
        Eigen::Isometry3d d = Eigen::Isometry3d::Identity();
        if (kind == 0)
          d.translation()[axis] = 1e-3;
        else
          d.linear() = Eigen::AngleAxisd(10e-3, Eigen::Vector3d::Unit(axis)).toRotationMatrix();
        pose(g, joint) = pose(g, joint) * d;
        EXPECT_LT(maxSpotChange(g, nominal()), 1e-12)
            << defectJointElements()[joint] << (kind == 0 ? " translation " : " rotation ") << axis;
      }
    }
  }
  EXPECT_EQ(null_motions, 18);
}

TEST(OpticalDefects, EachOfThe30IsARealDefect)
{
  // Measured at 0.1 mm / 0.1 mrad over ±0.12 rad (max spot change): source 89-103 µm, axes
  // 76-157 µm, mirrors 121-167 µm, work plane 6.0-100 µm, windows 0.106-0.107 µm. Every defect acts
  // (> 0.01 µm), and OPT's observation "window orientation defects are about 1000× less influential
  // than the others" holds: median of the others / window = ~900 (asserted 300-3000), and each
  // window defect is below 1/50 of every other one (the weakest other, work_plane.a, is 56×).
  std::vector<double> others;
  double window_max = 0.0;
  for (std::size_t k = 0; k < kDefectCount; ++k)
  {
    const double change = maxSpotChange(applyDefects(nominal(), single(k, 0.1)), nominal());
    EXPECT_GT(change, 0.01e-6) << defectLabel(k);
    if (defectLabel(k).rfind("window_", 0) == 0)
      window_max = std::max(window_max, change);
    else
      others.push_back(change);
  }
  ASSERT_EQ(others.size(), 26u);
  std::sort(others.begin(), others.end());
  const double median = 0.5 * (others[12] + others[13]);
  EXPECT_GT(median / window_max, 300.0);
  EXPECT_LT(median / window_max, 3000.0);
  EXPECT_GT(others.front() / window_max, 50.0);
}

TEST(OpticalDefects, NominalSetIsNominalBitForBit)
{
  const DefectSet set;
  EXPECT_TRUE(set.isNominal());
  EXPECT_EQ(set.name, "nominal");
  const OpticalGeometry g = applyDefects(nominal(), set);
  const auto a = poses(g);
  const auto b = poses(nominal());
  for (std::size_t k = 0; k < 8; ++k)
    EXPECT_EQ(std::memcmp(a[k]->matrix().data(), b[k]->matrix().data(), sizeof(double) * 16), 0) << k;
  // The shipped nominal file and name are the same set.
  const DefectSet file = loadDefectSet(kDefectsDir + "nominal.yaml");
  EXPECT_TRUE(file.isNominal());
  EXPECT_EQ(file.name, "nominal");
  EXPECT_TRUE(defectSetByName("nominal").isNominal());
  EXPECT_FALSE(single(29, 1e-300).isNominal());
}

TEST(OpticalDefects, WorkPlaneTranslationShiftsSpotsBack)
{
  // work_plane.x, y (mm) move the plane frame within its plane (nominal rotation = I): the beam
  // hits the same base point p, expressed in the moved frame, R^T (p − o − t) = spot − (dx, dy).
  // Tolerance 1e-12 m: rounding of ~0.2 m numbers.
  DefectSet set;
  set.values[defectIndex("work_plane.x")] = 1.5;
  set.values[defectIndex("work_plane.y")] = -0.7;
  const OpticalModel moved(applyDefects(nominal(), set), OpticsConfig());
  const OpticalModel base(nominal(), OpticsConfig());
  for (const Eigen::Vector2d& q : fieldAngles())
  {
    const Eigen::Vector2d shift = moved.spot(q) - base.spot(q);
    EXPECT_NEAR(shift.x(), -1.5e-3, 1e-12) << q.transpose();
    EXPECT_NEAR(shift.y(), 0.7e-3, 1e-12) << q.transpose();
  }
}

TEST(OpticalDefects, OptTable2FileAndCodeAreTheTable)
{
  // SPEC §4 / OPT table 2 transcribed again here, by label (independent of the code's order).
  const std::map<std::string, double> table = {
      {"source.y", -0.063},     {"source.z", -0.085},     {"source.b", -0.069},     {"source.c", -0.065},
      {"axis_x.y", -0.040},     {"axis_x.z", -0.023},     {"axis_x.a", 0.030},      {"axis_x.b", 0.063},
      {"axis_x.c", 0.053},      {"mirror_x.z", -0.025},   {"mirror_x.a", -0.062},   {"mirror_x.b", 0.029},
      {"axis_y.y", -0.099},     {"axis_y.z", -0.043},     {"axis_y.a", -0.028},     {"axis_y.b", 0.018},
      {"axis_y.c", -0.035},     {"mirror_y.z", 0.000},    {"mirror_y.a", -0.075},   {"mirror_y.b", 0.047},
      {"window_1.a", -0.069},   {"window_1.b", -0.013},   {"window_2.a", 0.066},    {"window_2.b", -0.028},
      {"work_plane.x", -0.085}, {"work_plane.y", 0.011},  {"work_plane.z", -0.045}, {"work_plane.a", -0.074},
      {"work_plane.b", 0.040},  {"work_plane.c", -0.003},
  };
  ASSERT_EQ(table.size(), 30u);
  const DefectSet code = optTable2DefectSet();
  const DefectSet file = loadDefectSet(kDefectsDir + "opt_table2.yaml");
  EXPECT_EQ(code.name, "opt_table2");
  EXPECT_EQ(file.name, "opt_table2");
  // Bit for bit: all three are the correctly rounded doubles of the same decimal literals.
  EXPECT_TRUE(sameBits(file, code));
  EXPECT_TRUE(sameBits(defectSetByName("opt_table2"), code));
  for (std::size_t k = 0; k < kDefectCount; ++k)
  {
    EXPECT_EQ(code.values[k], table.at(defectLabel(k))) << defectLabel(k);
    EXPECT_LE(std::abs(code.values[k]), 0.1) << defectLabel(k);  // drawn within ±0.1 mm / mrad
  }
  EXPECT_FALSE(code.isNominal());
}

TEST(OpticalDefects, YamlRoundTripIsExact)
{
  for (const DefectSet& set : {optTable2DefectSet(), randomDefectSet(7), randomDefectSet(99, 2.5, 1e-7), DefectSet()})
  {
    const std::string path = tempPath("round_trip.yaml");
    std::ofstream(path) << defectSetToYaml(set);
    const DefectSet back = loadDefectSet(path);
    EXPECT_EQ(back.name, set.name);
    EXPECT_TRUE(sameBits(back, set)) << set.name << "\n" << defectSetToYaml(set);
    std::filesystem::remove(path);
  }
  // Names with quotes, colons and non-ASCII text round-trip (parseDefectSet reads the text itself).
  DefectSet named = randomDefectSet(3);
  named.name = "Prüfstand 2: 'B' \"left\" # 1";
  EXPECT_EQ(parseDefectSet(defectSetToYaml(named), "text.yaml").name, named.name);
  // All 30 entries are written, in the file format of the issue.
  const std::string text = defectSetToYaml(optTable2DefectSet());
  EXPECT_NE(text.find("\nmirror_x:   {z: -0.025, a: -0.062, b: 0.029}\n"), std::string::npos) << text;
  EXPECT_NE(text.find("\nmirror_y:   {z: 0, a: -0.075, b: 0.047}\n"), std::string::npos) << text;
  EXPECT_NE(text.find("\nname: opt_table2\n"), std::string::npos) << text;
}

TEST(OpticalDefects, LoadOmittedIsZeroAndNameDefaultsToStem)
{
  const std::string path = tempPath("partial.yaml");
  std::ofstream(path) << "# comment\nmirror_x:\n  b: 0.25\n  a: -1e-2\nwindow_2:\nwork_plane: {z: 3}\n";
  const DefectSet set = loadDefectSet(path);
  EXPECT_EQ(set.name, "scanhead_test_optical_defects_partial");
  for (std::size_t k = 0; k < kDefectCount; ++k)
  {
    const std::string label = defectLabel(k);
    const double expected = label == "mirror_x.b"     ? 0.25
                            : label == "mirror_x.a"   ? -1e-2
                            : label == "work_plane.z" ? 3.0
                                                      : 0.0;
    EXPECT_EQ(set.values[k], expected) << label;
  }
  std::ofstream(path) << "";
  EXPECT_TRUE(loadDefectSet(path).isNominal());
  std::filesystem::remove(path);
}

TEST(OpticalDefects, LoadErrorsNameFileLineAndKey)
{
  struct Case
  {
    const char* name;
    const char* text;
    std::vector<std::string> expected;  // ":N:" means path + ":N:"
  };
  const Case cases[] = {
      {"element",
       "source: {y: 0.01}\nlaser_source: {y: 0}\n",
       {":2:", "unknown element 'laser_source'",
        "source, axis_x, mirror_x, axis_y, mirror_y, window_1, window_2, work_plane"}},
      {"component", "mirror_x:\n  z: 0.01\n  x: 0.02\n", {":3:", "unknown component 'mirror_x.x'", "z, a, b"}},
      {"component_flow", "source: {y: 0.1, a: 0.2}\n", {":1:", "'source.a'", "y, z, b, c"}},
      {"window", "window_1: {c: 0.1}\n", {":1:", "'window_1.c'", "window_1 has a, b"}},
      {"number", "axis_y:\n  b: abc\n", {":2:", "axis_y.b is not a number ('abc'"}},
      {"nan", "work_plane:\n  z: nan\n", {":2:", "work_plane.z is not finite ('nan'"}},
      {"yaml_nan", "work_plane:\n  a: .nan\n", {":2:", "work_plane.a is not a number ('.nan'"}},
      {"list", "work_plane:\n  x: [1, 2]\n", {":2:", "work_plane.x is not a number"}},
      {"not_map", "- a\n- b\n", {":1:", "not a map", "elements: source"}},
      {"element_not_map", "\nmirror_y: 3\n", {":2:", "mirror_y must be a map", "z, a, b"}},
      {"duplicate", "axis_x: {a: 1}\naxis_x: {b: 1}\n", {":2:", "duplicate key 'axis_x'"}},
      {"duplicate_component", "axis_x: {a: 1, a: 2}\n", {":1:", "duplicate key 'axis_x.a'"}},
      {"name", "name: [a]\n", {":1:", "name must be a non-empty string"}},
      // Found by fuzz_defect_set: names that did not survive defectSetToYaml.
      {"name_nul", "name: \"a\\0b\"\n", {":1:", "name must be printable UTF-8 text"}},
      {"name_bytes",
       "name: a\xff\xfe"
       "b\n",
       {":1:", "name must be printable UTF-8 text"}},
      {"aliases",
       "a: &a [1, 1, 1, 1, 1, 1, 1, 1]\nb: &b [*a, *a, *a, *a, *a, *a, *a, *a]\n"
       "c: &c [*b, *b, *b, *b, *b, *b, *b, *b]\nd: &d [*c, *c, *c, *c, *c, *c, *c, *c]\n"
       "e: [*d, *d, *d, *d, *d, *d, *d, *d]\n",
       {":", "YAML aliases expand to more than"}},
      {"yaml", "source: {y: 0.1\nmirror_x: {z: 1}\n", {"malformed YAML"}},
  };
  for (const Case& c : cases)
  {
    const std::string path = tempPath(std::string("bad_") + c.name + ".yaml");
    std::ofstream(path) << c.text;
    try
    {
      loadDefectSet(path);
      ADD_FAILURE() << c.name << ": accepted";
    }
    catch (const InputError& e)
    {
      const std::string message = e.what();
      EXPECT_EQ(message.rfind(path + ":", 0), 0u) << c.name << ": " << message;
      for (const std::string& part : c.expected)
      {
        const std::string needle = part.front() == ':' ? path + part : part;
        EXPECT_NE(message.find(needle), std::string::npos) << c.name << ": '" << needle << "' in " << message;
      }
    }
    std::filesystem::remove(path);
  }
  try
  {
    loadDefectSet(tempPath("missing.yaml"));
    ADD_FAILURE() << "missing file accepted";
  }
  catch (const InputError& e)
  {
    EXPECT_NE(std::string(e.what()).find(tempPath("missing.yaml") + ": cannot open"), std::string::npos) << e.what();
  }
}

TEST(OpticalDefects, RandomSetsArePortableAndBounded)
{
  // splitmix64 → (u >> 11)·2^-53 → bound·(2u − 1): integer arithmetic and one rounding, so these
  // exact values on every platform (a change of generator or of the draw order fails here).
  const DefectSet seven = randomDefectSet(7);
  EXPECT_EQ(seven.name, "random_seed7");
  EXPECT_EQ(seven.values[0], -0.022034050321745702);
  EXPECT_EQ(seven.values[1], -0.096642341094368783);
  EXPECT_EQ(seven.values[29], -0.016993716639112134);
  EXPECT_TRUE(sameBits(randomDefectSet(7), seven));
  EXPECT_TRUE(sameBits(defectSetByName("random:seed=7"), seven));
  EXPECT_EQ(defectSetByName("random:seed=7").name, "random_seed7");

  // Different seeds: every component differs.
  const DefectSet eight = randomDefectSet(8);
  for (std::size_t k = 0; k < kDefectCount; ++k)
    EXPECT_NE(eight.values[k], seven.values[k]) << defectLabel(k);

  // Bounds, per kind, and uniformity: over 400 seeds the mean |v|/B of a uniform law on ±B is 1/2
  // (standard error 0.29/√(400·n) < 0.004 with n = 12 or 18: ±0.02 is 5σ) and the extremes
  // come within 1 % of the bounds.
  double sum_mm = 0.0;
  double sum_mrad = 0.0;
  double max_mm = 0.0;
  double max_mrad = 0.0;
  int n_mm = 0;
  int n_mrad = 0;
  for (std::uint64_t seed = 1000; seed < 1400; ++seed)
  {
    const DefectSet set = randomDefectSet(seed, 0.05, 0.2);
    for (std::size_t k = 0; k < kDefectCount; ++k)
    {
      const double v = std::abs(set.values[k]);
      if (defectComponents()[k].rotation())
      {
        ASSERT_LE(v, 0.2);
        sum_mrad += v / 0.2;
        max_mrad = std::max(max_mrad, v);
        ++n_mrad;
      }
      else
      {
        ASSERT_LE(v, 0.05);
        sum_mm += v / 0.05;
        max_mm = std::max(max_mm, v);
        ++n_mm;
      }
    }
  }
  EXPECT_NEAR(sum_mm / n_mm, 0.5, 0.02);
  EXPECT_NEAR(sum_mrad / n_mrad, 0.5, 0.02);
  EXPECT_GT(max_mm, 0.99 * 0.05);
  EXPECT_GT(max_mrad, 0.99 * 0.2);
  EXPECT_TRUE(randomDefectSet(3, 0.0, 0.0).isNominal());
  EXPECT_THROW(randomDefectSet(3, -1.0, 0.1), ConfigError);

  // Bounds in the name when they are not OPT's ±0.1; the spec form gives the same set.
  const DefectSet wide = defectSetByName("random:seed=7,mm=0.2,mrad=0.05");
  EXPECT_TRUE(sameBits(wide, randomDefectSet(7, 0.2, 0.05)));
  EXPECT_EQ(wide.name, "random_seed7_mm0.2_mrad0.05");
  EXPECT_TRUE(
      sameBits(defectSetByName("random:mrad=0.1,seed=18446744073709551615"), randomDefectSet(18446744073709551615ULL)));
}

TEST(OpticalDefects, DefectSetByNameFormsAndErrors)
{
  EXPECT_TRUE(sameBits(defectSetByName(kDefectsDir + "opt_table2.yaml"), optTable2DefectSet()));
  const char* const bad[] = {"typical",
                             "random",
                             "random:",
                             "random:seed=x",
                             "random:seed=-1",
                             "random:mm=0.1",
                             "random:seed=1,foo=2",
                             "random:seed=1,mm=-1",
                             "random:seed=1,seed=2",
                             "random:seed=18446744073709551616",
                             "random:seed=1,mm"};
  for (const char* spec : bad)
  {
    try
    {
      defectSetByName(spec);
      ADD_FAILURE() << spec << ": accepted";
    }
    catch (const InputError& e)
    {
      const std::string message = e.what();
      EXPECT_NE(message.find(std::string("'") + spec + "'"), std::string::npos) << message;
      EXPECT_NE(message.find("nominal, opt_table2, random:seed=N[,mm=B][,mrad=B]"), std::string::npos) << message;
    }
  }
  EXPECT_THROW(defectSetByName(tempPath("missing.yaml")), InputError);
}

TEST(OpticalDefects, UrdfWithDefectsIsTheAppliedMachine)
{
  // Independent path: urdfdom composes the written origins (its own rpy → quaternion → matrix);
  // rounding of the two rotation constructions differs by ~1e-16: poses within 1e-15 (m and
  // unitless), spots within 1e-12 m at random angles over the joint range.
  const std::string text = readFile(kUrdfPath);
  std::mt19937 random(20240605u);  // mt19937's sequence is fixed by the standard
  for (const DefectSet& set : {optTable2DefectSet(), randomDefectSet(7), randomDefectSet(11, 1.0, 1.0)})
  {
    const std::string urdf = urdfWithDefects(text, set, "scanhead.urdf");
    const OpticalGeometry read = geometryFromUrdf(urdf, set.name + ".urdf");
    const OpticalGeometry applied = applyDefects(nominal(), set);
    const auto a = poses(applied);
    const auto b = poses(read);
    for (std::size_t k = 0; k < 8; ++k)
      EXPECT_LT((a[k]->matrix() - b[k]->matrix()).cwiseAbs().maxCoeff(), 1e-15) << set.name << " " << k;
    const OpticalModel ma(applied, OpticsConfig());
    const OpticalModel mb(read, OpticsConfig());
    double worst = 0.0;
    for (int n = 0; n < 200; ++n)
    {
      const Eigen::Vector2d q(0.17 * (2.0 * random() / 4294967295.0 - 1.0),
                              0.17 * (2.0 * random() / 4294967295.0 - 1.0));
      worst = std::max(worst, (ma.spot(q) - mb.spot(q)).norm());
    }
    EXPECT_LT(worst, 1e-12) << set.name;
    EXPECT_GT(maxSpotChange(applied, nominal()), 50e-6) << set.name;  // and the machine is defective

    // Only the 8 defect joint origins changed: the same lines elsewhere, byte for byte.
    std::istringstream before(text);
    std::istringstream after(urdf);
    std::string line_before;
    std::string line_after;
    int changed = 0;
    std::string joint;
    while (std::getline(before, line_before))
    {
      ASSERT_TRUE(static_cast<bool>(std::getline(after, line_after)));
      if (line_before.find("<joint name=") != std::string::npos)
        joint = line_before;
      if (line_before != line_after)
      {
        ++changed;
        EXPECT_NE(joint.find("_defect_joint\""), std::string::npos) << line_after;
        EXPECT_NE(line_after.find("<origin xyz=\""), std::string::npos) << line_after;
      }
    }
    EXPECT_FALSE(static_cast<bool>(std::getline(after, line_after)));
    EXPECT_EQ(changed, 8) << set.name;
  }
  // The nominal set leaves the URDF as it is.
  EXPECT_EQ(urdfWithDefects(text, DefectSet(), "scanhead.urdf"), text);
}

TEST(OpticalDefects, UrdfWithDefectsEditsOnlyTheOriginsWhateverTheLayout)
{
  // TinyXML reports where each node starts by (row, column): line ends, tabs and multi-byte
  // characters must not shift the edits. The same URDF with CRLF line ends, tab indentation and
  // UTF-8 in a comment on a joint's line gives the same output up to those changes.
  const std::string text = readFile(kUrdfPath);
  const DefectSet set = optTable2DefectSet();
  const std::string expected = urdfWithDefects(text, set, "lf.urdf");
  auto replaceAll = [](std::string s, const std::string& from, const std::string& to) {
    for (std::size_t at = s.find(from); at != std::string::npos; at = s.find(from, at + to.size()))
      s.replace(at, from.size(), to);
    return s;
  };
  const std::string joint = "<joint name=\"mirror_x_defect_joint\" type=\"fixed\">";
  const std::string marked = joint + "\t<!-- \xc2\xb5\xc2\xb5 -->";
  for (const auto& [from, to] :
       std::vector<std::pair<std::string, std::string>>{{"\n", "\r\n"}, {"\n    ", "\n\t\t"}, {joint, marked}})
  {
    const std::string variant = replaceAll(text, from, to);
    ASSERT_NE(variant, text) << "'" << to << "'";
    EXPECT_EQ(urdfWithDefects(variant, set, "variant.urdf"), replaceAll(expected, from, to)) << "'" << to << "'";
  }
  // An origin with a body is replaced whole; a joint closed on its last content line gets its
  // origin just before </joint>.
  const std::string origin = "<origin xyz=\"0 0 0\" rpy=\"0 0 0\"/>";
  const std::size_t at = text.find(origin, text.find("<joint name=\"window_1_defect_joint\""));
  ASSERT_NE(at, std::string::npos);
  const std::string with_body =
      std::string(text).replace(at, origin.size(), "<origin xyz='0 0 0' rpy=\"0 0 0\" > </origin >");
  EXPECT_EQ(urdfWithDefects(with_body, set, "body.urdf"), expected);
  const std::size_t line = text.rfind('\n', at);
  const std::size_t close = text.find("</joint>", at);
  const std::string inline_close = text.substr(0, line) + text.substr(close);  // <child .../></joint>
  const std::string out = urdfWithDefects(inline_close, set, "inline.urdf");
  const std::string head = "<child link=\"window_1_defect\"/><origin xyz=\"0 0 0\" rpy=\"";
  const std::size_t edited = out.find(head);
  ASSERT_NE(edited, std::string::npos) << out.substr(line - 80, 240);
  EXPECT_EQ(out.find("\"/></joint>", edited), out.find('>', edited + head.size()) - 2);
  EXPECT_EQ(out.substr(0, line), expected.substr(0, line));
  // Not well-formed: the parser's message, with the source's name.
  try
  {
    urdfWithDefects(text.substr(0, close), set, "cut.urdf");
    ADD_FAILURE() << "accepted";
  }
  catch (const InputError& e)
  {
    EXPECT_EQ(std::string(e.what()).rfind("cut.urdf: not well-formed XML (TinyXML: ", 0), 0u) << e.what();
  }
}

TEST(OpticalDefects, UrdfWithDefectsEdgeCases)
{
  const std::string text = readFile(kUrdfPath);
  // A defect joint without <origin> (identity in URDF) gets one.
  const std::string origin = "    <origin xyz=\"0 0 0\" rpy=\"0 0 0\"/>\n";
  const std::size_t at = text.find(origin, text.find("<joint name=\"mirror_y_defect_joint\""));
  ASSERT_NE(at, std::string::npos);
  const std::string no_origin = std::string(text).erase(at, origin.size());
  DefectSet set;
  set.values[defectIndex("mirror_y.a")] = 0.5;
  const OpticalGeometry read = geometryFromUrdf(urdfWithDefects(no_origin, set, "no_origin.urdf"), "x");
  EXPECT_LT((read.mirror_y.matrix() - applyDefects(nominal(), set).mirror_y.matrix()).cwiseAbs().maxCoeff(), 1e-15);
  // A commented-out decoy is not edited.
  const std::string decoy = "<!-- <joint name=\"work_plane_defect_joint\"><origin xyz=\"9 9 9\"/></joint> -->\n";
  const std::string with_decoy = decoy + text;
  EXPECT_EQ(urdfWithDefects(with_decoy, set, "decoy.urdf").substr(0, decoy.size()), decoy);
  // A missing defect joint names the source and the joint.
  const std::string renamed = [&] {
    std::string s = text;
    const std::size_t j = s.find("\"window_2_defect_joint\"");
    s.replace(j, 23, "\"window_2_defect_jnt\"");
    return s;
  }();
  try
  {
    urdfWithDefects(renamed, set, "renamed.urdf");
    ADD_FAILURE() << "accepted";
  }
  catch (const InputError& e)
  {
    EXPECT_NE(std::string(e.what()).find("renamed.urdf: missing joint 'window_2_defect_joint'"), std::string::npos)
        << e.what();
  }
}
}  // namespace scanhead
