/// \file defect_catalog.cpp
/// \brief The 30 defects, their mapping onto our defect joints (the table in defect_catalog.hpp),
/// their application to a geometry, OPT table 2 and seeded random sets.
#include "scanhead/optics/defect_catalog.hpp"

#include <Eigen/Geometry>
#include <cmath>
#include <stdexcept>

#include "scanhead/common/errors.hpp"
#include "scanhead/common/number_text.hpp"
#include "scanhead/common/random.hpp"

namespace scanhead
{
namespace
{
constexpr std::size_t kElementCount = 8;

/// One row of the mapping table (defect_catalog.hpp): OPT component → our defect joint, axis, sign.
struct Mapping
{
  std::size_t element;  ///< index in defectElements() / defectJointElements()
  char component;       ///< OPT: x y z a b c
  int our_axis;         ///< 0, 1, 2: x, y, z of the translation, or roll, pitch, yaw
  double sign;          ///< +1 (cyclic relabelling)
};

// clang-format off
const Mapping kMapping[kDefectCount] = {
  { 0, 'y', 1, 1.0 }, { 0, 'z', 2, 1.0 }, { 0, 'b', 1, 1.0 }, { 0, 'c', 2, 1.0 },                      // source
  { 1, 'y', 0, 1.0 }, { 1, 'z', 1, 1.0 }, { 1, 'a', 2, 1.0 }, { 1, 'b', 0, 1.0 }, { 1, 'c', 1, 1.0 },  // axis_x
  { 2, 'z', 0, 1.0 }, { 2, 'a', 1, 1.0 }, { 2, 'b', 2, 1.0 },                                          // mirror_x
  { 3, 'y', 0, 1.0 }, { 3, 'z', 1, 1.0 }, { 3, 'a', 2, 1.0 }, { 3, 'b', 0, 1.0 }, { 3, 'c', 1, 1.0 },  // axis_y
  { 4, 'z', 0, 1.0 }, { 4, 'a', 1, 1.0 }, { 4, 'b', 2, 1.0 },                                          // mirror_y
  { 5, 'a', 0, 1.0 }, { 5, 'b', 1, 1.0 },                                                              // window_1
  { 6, 'a', 0, 1.0 }, { 6, 'b', 1, 1.0 },                                                              // window_2
  { 7, 'x', 0, 1.0 }, { 7, 'y', 1, 1.0 }, { 7, 'z', 2, 1.0 },                                          // work_plane
  { 7, 'a', 0, 1.0 }, { 7, 'b', 1, 1.0 }, { 7, 'c', 2, 1.0 },
};
// clang-format on

bool isRotation(char component)
{
  return component == 'a' || component == 'b' || component == 'c';
}

/// The pose each element's defect applies to, in defectJointElements() order.
Eigen::Isometry3d& pose(OpticalGeometry& g, std::size_t element)
{
  Eigen::Isometry3d* const members[kElementCount] = {&g.source,   &g.mount_x,  &g.mirror_x, &g.mount_y,
                                                     &g.mirror_y, &g.window_1, &g.window_2, &g.work_plane};
  return *members[element];
}
}  // namespace

const std::array<const char*, 8>& defectElements()
{
  static const std::array<const char*, 8> keys = {"source",   "axis_x",   "mirror_x", "axis_y",
                                                  "mirror_y", "window_1", "window_2", "work_plane"};
  return keys;
}

const std::array<DefectComponent, kDefectCount>& defectComponents()
{
  static const std::array<DefectComponent, kDefectCount> components = [] {
    std::array<DefectComponent, kDefectCount> c{};
    for (std::size_t k = 0; k < kDefectCount; ++k)
      c[k] = DefectComponent{defectElements()[kMapping[k].element], kMapping[k].component};
    return c;
  }();
  return components;
}

std::string defectLabel(std::size_t index)
{
  if (index >= kDefectCount)
    throw std::out_of_range("defectLabel: index " + std::to_string(index) + " >= 30");
  return std::string(defectElements()[kMapping[index].element]) + "." + kMapping[index].component;
}

std::size_t defectIndex(const std::string& label)
{
  std::string known;
  for (std::size_t k = 0; k < kDefectCount; ++k)
  {
    if (defectLabel(k) == label)
      return k;
    known += (k ? ", " : "") + defectLabel(k);
  }
  throw InputError("unknown defect '" + label + "' (the 30: " + known + ")");
}

bool DefectSet::isNominal() const
{
  for (double v : values)
  {
    if (v != 0.0)
      return false;
  }
  return true;
}

const std::array<std::string, 8>& defectJointElements()
{
  static const std::array<std::string, 8> names = {"laser_source", "galvo_x_mount", "mirror_x", "galvo_y_mount",
                                                   "mirror_y",     "window_1",      "window_2", "work_plane"};
  return names;
}

std::array<ElementDefect, 8> elementDefects(const DefectSet& set)
{
  std::array<ElementDefect, 8> out{};
  for (std::size_t k = 0; k < kDefectCount; ++k)
  {
    const Mapping& m = kMapping[k];
    // mm → m, mrad → rad; "+ 0.0" turns a -0 into +0 (so "-0" never reaches a URDF).
    const double si = m.sign * set.values[k] / 1000.0 + 0.0;
    ElementDefect& d = out[m.element];
    (isRotation(m.component) ? d.rotation_rad : d.translation_m)[m.our_axis] = si;
  }
  return out;
}

OpticalGeometry applyDefects(const OpticalGeometry& nominal, const DefectSet& set)
{
  OpticalGeometry g = nominal;
  const std::array<ElementDefect, 8> defects = elementDefects(set);
  for (std::size_t k = 0; k < kElementCount; ++k)
  {
    const ElementDefect& d = defects[k];
    if (d.translation_m.isZero(0.0) && d.rotation_rad.isZero(0.0))
      continue;  // identity: leave the pose bit-for-bit as it is
    // D = Trans(t) · Rz(yaw) · Ry(pitch) · Rx(roll) (URDF rpy: fixed-axis x, y, z rotations).
    Eigen::Isometry3d displacement = Eigen::Isometry3d::Identity();
    displacement.translation() = d.translation_m;
    displacement.linear() = (Eigen::AngleAxisd(d.rotation_rad.z(), Eigen::Vector3d::UnitZ()) *
                             Eigen::AngleAxisd(d.rotation_rad.y(), Eigen::Vector3d::UnitY()) *
                             Eigen::AngleAxisd(d.rotation_rad.x(), Eigen::Vector3d::UnitX()))
                                .toRotationMatrix();
    Eigen::Isometry3d& p = pose(g, k);
    p = p * displacement;
  }
  return g;
}

DefectSet optTable2DefectSet()
{
  // OPT table 2 ("Tableau 2", values drawn at random within ±0.1 mm / ±0.1 mrad), mm and mrad,
  // in the order of defectComponents(). config/defects/opt_table2.yaml holds the same numbers.
  DefectSet set;
  set.name = "opt_table2";
  set.values = {
      -0.063, -0.085, -0.069, -0.065,                  // source y z b c
      -0.040, -0.023, 0.030,  0.063,  0.053,           // axis_x y z a b c
      -0.025, -0.062, 0.029,                           // mirror_x z a b
      -0.099, -0.043, -0.028, 0.018,  -0.035,          // axis_y y z a b c
      0.000,  -0.075, 0.047,                           // mirror_y z a b
      -0.069, -0.013,                                  // window_1 a b
      0.066,  -0.028,                                  // window_2 a b
      -0.085, 0.011,  -0.045, -0.074, 0.040,  -0.003,  // work_plane x y z a b c
  };
  return set;
}

DefectSet randomDefectSet(std::uint64_t seed, double bound_mm, double bound_mrad)
{
  if (!(std::isfinite(bound_mm) && bound_mm >= 0.0) || !(std::isfinite(bound_mrad) && bound_mrad >= 0.0))
    throw ConfigError("random defect set: the bounds must be finite and >= 0 (got mm=" + shortestText(bound_mm) +
                      ", mrad=" + shortestText(bound_mrad) + ")");
  DefectSet set;
  set.name = "random_seed" + std::to_string(seed);
  if (bound_mm != 0.1 || bound_mrad != 0.1)
    set.name += "_mm" + shortestText(bound_mm) + "_mrad" + shortestText(bound_mrad);
  SplitMix64 random(seed);
  for (std::size_t k = 0; k < kDefectCount; ++k)
  {
    // u in [0, 1) with 53 random bits; 2u − 1 in [−1, 1) is exact, so one rounding (× bound).
    const double u = random.uniformClosedOpen();
    const double bound = isRotation(kMapping[k].component) ? bound_mrad : bound_mm;
    set.values[k] = bound * (2.0 * u - 1.0);
  }
  return set;
}
}  // namespace scanhead
