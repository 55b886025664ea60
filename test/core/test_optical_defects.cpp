/// \file test_optical_defects.cpp
/// \brief Assembly defects (SPEC §4): frame algebra against urdfdom and against geometry, the
/// typical set and its file, defect-set file errors.
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "scanhead/core/errors.hpp"
#include "scanhead/core/number_text.hpp"
#include "scanhead/core/optical_defects.hpp"

#ifndef SCANHEAD_SOURCE_DIR
#error "SCANHEAD_SOURCE_DIR (repository root) must be defined"
#endif

namespace scanhead
{
namespace
{
const std::string kUrdfPath = std::string(SCANHEAD_SOURCE_DIR) + "/urdf/scanhead.urdf";

std::string readFile(const std::string& path)
{
  std::ifstream in(path);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

const OpticalGeometry& nominal()
{
  static const OpticalGeometry g = geometryFromUrdfFile(kUrdfPath);
  return g;
}

std::array<const Eigen::Isometry3d*, 8> poses(const OpticalGeometry& g)
{
  return { &g.source, &g.mount_x, &g.mirror_x, &g.mount_y, &g.mirror_y, &g.window_1, &g.window_2, &g.work_plane };
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

DefectSet single(const std::string& element, const Eigen::Vector3d& xyz_m, const Eigen::Vector3d& rpy_rad)
{
  DefectSet set;
  for (std::size_t k = 0; k < 8; ++k)
  {
    if (defectElementNames()[k] == element)
    {
      set.elements[k].translation_m = xyz_m;
      set.elements[k].rotation_rad = rpy_rad;
    }
  }
  return set;
}

std::string tempPath(const std::string& name)
{
  return (std::filesystem::temp_directory_path() / ("scanhead_test_optical_defects_" + name)).string();
}
}  // namespace

TEST(OpticalDefects, ElementNames)
{
  const std::array<std::string, 8> expected = { "laser_source", "galvo_x_mount", "mirror_x", "galvo_y_mount",
                                                "mirror_y",     "window_1",      "window_2", "work_plane" };
  EXPECT_EQ(defectElementNames(), expected);
}

TEST(OpticalDefects, ZeroSetIsNominalBitForBit)
{
  const OpticalGeometry g = applyDefects(nominal(), DefectSet());
  const auto a = poses(g);
  const auto b = poses(nominal());
  for (std::size_t k = 0; k < 8; ++k)
    EXPECT_EQ(std::memcmp(a[k]->matrix().data(), b[k]->matrix().data(), sizeof(double) * 16), 0) << k;
  const OpticalModel ma(g, OpticsConfig());
  const OpticalModel mb(nominal(), OpticsConfig());
  for (const Eigen::Vector2d& q : fieldAngles())
  {
    const Eigen::Vector2d sa = ma.spot(q);
    const Eigen::Vector2d sb = mb.spot(q);
    EXPECT_EQ(std::memcmp(sa.data(), sb.data(), sizeof(double) * 2), 0) << q.transpose();
  }
}

TEST(OpticalDefects, SameAsWritingTheDefectJointOrigins)
{
  // Independent path: the typical set written into each `<element>_defect_joint` origin of the URDF
  // and composed by urdfdom (its own rpy -> quaternion -> matrix). Rounding of the two rotation
  // constructions differs by ~1e-16; poses agree to 1e-15 (m and unitless), spots to 1e-12 m.
  const char* const joints[8] = { "laser_source_defect_joint", "galvo_x_mount_defect_joint", "mirror_x_defect_joint",
                                  "galvo_y_mount_defect_joint", "mirror_y_defect_joint",     "window_1_defect_joint",
                                  "window_2_defect_joint",      "work_plane_defect_joint" };
  const DefectSet set = typicalDefectSet();
  std::string xml = readFile(kUrdfPath);
  for (std::size_t k = 0; k < 8; ++k)
  {
    const ElementDefect& d = set.elements[k];
    auto triple = [](const Eigen::Vector3d& v) {
      return fullPrecisionText(v.x()) + " " + fullPrecisionText(v.y()) + " " + fullPrecisionText(v.z());
    };
    const std::size_t at = xml.find("<joint name=\"" + std::string(joints[k]) + "\"");
    ASSERT_NE(at, std::string::npos) << joints[k];
    const std::size_t begin = xml.find("<origin", at);
    const std::size_t end = xml.find("/>", begin) + 2;
    xml.replace(begin, end - begin,
                "<origin xyz=\"" + triple(d.translation_m) + "\" rpy=\"" + triple(d.rotation_rad) + "\"/>");
  }
  const OpticalGeometry from_urdf = geometryFromUrdf(xml, "defective.urdf");
  const OpticalGeometry applied = applyDefects(nominal(), set);
  const auto a = poses(applied);
  const auto b = poses(from_urdf);
  for (std::size_t k = 0; k < 8; ++k)
    EXPECT_LT((a[k]->matrix() - b[k]->matrix()).cwiseAbs().maxCoeff(), 1e-15) << defectElementNames()[k];
  EXPECT_LT(maxSpotChange(applied, from_urdf), 1e-12);
  // And the set does act: OPT's defects move the spot by ~0.1 mm (measured 264 µm at most).
  EXPECT_GT(maxSpotChange(applied, nominal()), 50e-6);
}

TEST(OpticalDefects, WorkPlaneTranslationShiftsSpotsBack)
{
  // P_plane -> P_plane·Trans(t), t = (dx, dy, 0): the plane keeps its height and orientation
  // (nominal rotation = I), so the beam hits the same base point p; the spot is expressed in the
  // new frame, R^T (p − o − t) = spot − (dx, dy). Tolerance 1e-12 m: rounding of ~0.2 m numbers.
  const double dx = 1.5e-3;
  const double dy = -0.7e-3;
  const OpticalModel moved(applyDefects(nominal(), single("work_plane", { dx, dy, 0.0 }, Eigen::Vector3d::Zero())),
                           OpticsConfig());
  const OpticalModel base(nominal(), OpticsConfig());
  for (const Eigen::Vector2d& q : fieldAngles())
  {
    const Eigen::Vector2d shift = moved.spot(q) - base.spot(q);
    EXPECT_NEAR(shift.x(), -dx, 1e-12) << q.transpose();
    EXPECT_NEAR(shift.y(), -dy, 1e-12) << q.transpose();
  }
}

TEST(OpticalDefects, MotionsThatKeepTheSurfaceDoNothing)
{
  // Geometry, not bookkeeping: moving the source along its own beam (+x), sliding a mirror in its
  // plane (y, z of its frame) or spinning it about its normal (roll), sliding a window in its
  // plane (x, y) or spinning it about its normal (yaw), and moving a galvo mount along its axis
  // (z), leave every ray unchanged. 1 mm / 10 mrad motions; tolerance 1e-12 m (rounding).
  const Eigen::Vector3d zero = Eigen::Vector3d::Zero();
  EXPECT_LT(maxSpotChange(applyDefects(nominal(), single("laser_source", { 1e-3, 0, 0 }, zero)), nominal()), 1e-12);
  EXPECT_LT(maxSpotChange(applyDefects(nominal(), single("laser_source", zero, { 10e-3, 0, 0 })), nominal()), 1e-12);
  for (const char* mirror : { "mirror_x", "mirror_y" })
  {
    EXPECT_LT(maxSpotChange(applyDefects(nominal(), single(mirror, { 0, 1e-3, -1e-3 }, zero)), nominal()), 1e-12);
    EXPECT_LT(maxSpotChange(applyDefects(nominal(), single(mirror, zero, { 10e-3, 0, 0 })), nominal()), 1e-12);
  }
  for (const char* window : { "window_1", "window_2" })
    EXPECT_LT(maxSpotChange(applyDefects(nominal(), single(window, { 1e-3, -1e-3, 0 }, { 0, 0, 10e-3 })), nominal()),
              1e-12);
  for (const char* mount : { "galvo_x_mount", "galvo_y_mount" })
    EXPECT_LT(maxSpotChange(applyDefects(nominal(), single(mount, { 0, 0, 1e-3 }, zero)), nominal()), 1e-12);
  // ... while the components the typical set uses do act (each > 1 µm somewhere at 0.1 mm /
  // 0.1 mrad; windows excepted, OPT: ~1000x less influential).
  EXPECT_GT(maxSpotChange(applyDefects(nominal(), single("mirror_x", { 0.1e-3, 0, 0 }, zero)), nominal()), 1e-6);
  EXPECT_GT(maxSpotChange(applyDefects(nominal(), single("mirror_y", zero, { 0, 0.1e-3, 0 })), nominal()), 1e-6);
  EXPECT_GT(maxSpotChange(applyDefects(nominal(), single("galvo_x_mount", zero, { 0, 0, 0.1e-3 })), nominal()), 1e-6);
}

TEST(OpticalDefects, TypicalSetFileEqualsTypicalSet)
{
  const DefectSet file = loadDefectSet(std::string(SCANHEAD_SOURCE_DIR) + "/config/defects/typical.yaml");
  const DefectSet code = typicalDefectSet();
  EXPECT_EQ(file.name, "typical");
  EXPECT_EQ(code.name, "typical");
  for (std::size_t k = 0; k < 8; ++k)
  {
    // Bit-for-bit: both are the correctly rounded doubles of the same decimal literals.
    EXPECT_EQ(std::memcmp(file.elements[k].translation_m.data(), code.elements[k].translation_m.data(), 24), 0)
        << defectElementNames()[k];
    EXPECT_EQ(std::memcmp(file.elements[k].rotation_rad.data(), code.elements[k].rotation_rad.data(), 24), 0)
        << defectElementNames()[k];
    // OPT table 2: every value within ±0.1 mm and ±0.1 mrad.
    EXPECT_LE(code.elements[k].translation_m.cwiseAbs().maxCoeff(), 0.1e-3);
    EXPECT_LE(code.elements[k].rotation_rad.cwiseAbs().maxCoeff(), 0.1e-3);
  }
  // 30 non-zero... OPT's mirror_y z is 0.000: 29 non-zero components.
  int nonzero = 0;
  for (const ElementDefect& d : code.elements)
    nonzero += static_cast<int>((d.translation_m.array() != 0.0).count() + (d.rotation_rad.array() != 0.0).count());
  EXPECT_EQ(nonzero, 29);
}

TEST(OpticalDefects, LoadOmittedIsZeroAndNameDefaultsToStem)
{
  const std::string path = tempPath("partial.yaml");
  std::ofstream(path) << "mirror_x:\n  rpy: [0.0, 1.0e-4, -2.0e-4]\nwork_plane: {xyz: [1e-5, 0, 0]}\n";
  const DefectSet set = loadDefectSet(path);
  EXPECT_EQ(set.name, "scanhead_test_optical_defects_partial");
  EXPECT_EQ(set.elements[2].rotation_rad, Eigen::Vector3d(0.0, 1.0e-4, -2.0e-4));
  EXPECT_EQ(set.elements[2].translation_m, Eigen::Vector3d::Zero());
  EXPECT_EQ(set.elements[7].translation_m, Eigen::Vector3d(1e-5, 0, 0));
  for (std::size_t k : { 0, 1, 3, 4, 5, 6 })
  {
    EXPECT_EQ(set.elements[k].translation_m, Eigen::Vector3d::Zero());
    EXPECT_EQ(set.elements[k].rotation_rad, Eigen::Vector3d::Zero());
  }
  std::filesystem::remove(path);
}

TEST(OpticalDefects, LoadErrorsNameFileLineAndKey)
{
  struct Case
  {
    const char* name;
    const char* text;
    std::vector<std::string> expected;
  };
  const Case cases[] = {
    { "element", "laser_source: {xyz: [0, 0, 0]}\nmirror_z:\n  xyz: [0, 0, 0]\n",
      { ":2:", "unknown element 'mirror_z'", "laser_source, galvo_x_mount, mirror_x, galvo_y_mount, mirror_y, "
                                             "window_1, window_2, work_plane" } },
    { "key", "mirror_x:\n  xyz: [0, 0, 0]\n  xyzz: [0, 0, 0]\n",
      { ":3:", "unknown key 'mirror_x.xyzz'", "valid: xyz [m], rpy [rad]" } },
    { "number", "window_1:\n  rpy: [0, abc, 0]\n", { ":2:", "window_1.rpy[1] is not a number ('abc')" } },
    { "nan", "window_1:\n  rpy: [0, .nan, 0]\n", { ":2:", "window_1.rpy[1]", "not" } },
    { "length", "work_plane:\n  xyz: [0, 0]\n", { ":2:", "work_plane.xyz must be a list of 3 numbers" } },
    { "not_map", "- a\n- b\n", { ":1:", "a defect set is a map" } },
    { "element_not_map", "mirror_y: 3\n", { ":1:", "mirror_y must be a map" } },
    { "yaml", "mirror_x: {xyz: [0, 0\n", { "malformed YAML" } },
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
      EXPECT_EQ(message.rfind(path, 0), 0u) << c.name << ": " << message;
      for (const std::string& part : c.expected)
      {
        const std::string needle = part.front() == ':' ? path + part : part;
        EXPECT_NE(message.find(needle), std::string::npos) << c.name << ": '" << needle << "' in " << message;
      }
    }
    std::filesystem::remove(path);
  }
  EXPECT_THROW(loadDefectSet(tempPath("missing.yaml")), InputError);
}
}  // namespace scanhead
