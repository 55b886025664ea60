/// \file optical_defects.cpp
/// \brief Assembly defects of the optical elements (SPEC §4, OPT §3): apply, read, typical set.
///
/// Element ↔ OpticalGeometry member (urdf/scanhead.urdf, optical_geometry_urdf.cpp):
///   laser_source  → source    (laser_source_defect in scanhead_base; beam along +x)
///   galvo_x_mount → mount_x   (galvo_x_mount_defect in scanhead_base; rotor axis +z)
///   mirror_x      → mirror_x  (mirror_x_defect in the galvo_x rotor frame; +x = surface normal)
///   galvo_y_mount → mount_y, mirror_y → mirror_y (likewise for galvo Y)
///   window_1, window_2 → window_1, window_2 (window_*_defect in scanhead_base; +z = face normal)
///   work_plane    → work_plane (work_plane_defect in scanhead_base; spots in this frame)
/// Each member is the product of the URDF fixed-joint origins down to the defect link, the last
/// being `<element>_defect_joint` (identity in the nominal URDF), so right-multiplying it by D is
/// the same as writing D into that joint's origin. (mount_* also carry the galvo joint origin
/// after the defect joint; it is identity in our URDF.)
///
/// typicalDefectSet(): the 30 values of OPT table 2 (seeds/001_6db5768eacf0c62f.txt, "Tableau 2",
/// "générées aléatoirement entre ± 0.1 mm et ± 0.1 mrad", the machine of OPT figure 6; SPEC §4).
/// OPT lists per element only the components that act on the spot, in its own frames: the beam
/// along OPT x for the source, the rotation axis along OPT x for the galvo axes (no x
/// translation), the normal along OPT z for mirrors, windows and the plane. Our frames put the
/// rotation axis on z and the mirror normal on x, so each value goes to the component of our frame
/// that plays the same role (a cyclic relabelling of the axes, which keeps rotations right-handed):
///   source, windows, work plane: as written (x y z a b c → x y z roll pitch yaw);
///   galvo mounts (OPT x = axis → our z): OPT y z → our x y; OPT a b c → our yaw roll pitch;
///   mirrors (OPT z = normal → our x): OPT z → our x; OPT a b → our pitch yaw.
/// Hence every value acts (placed literally, the mirrors' z translation and a rotation would slide
/// or spin the mirror in its own plane and do nothing). config/defects/typical.yaml holds the same
/// numbers.
#include "scanhead/core/optical_defects.hpp"

#include <Eigen/Geometry>
#include <fstream>
#include <sstream>
#include <yaml-cpp/yaml.h>

#include "scanhead/core/errors.hpp"
#include "scanhead/core/number_text.hpp"

namespace scanhead
{
namespace
{
/// The pose each element's defect applies to, in defectElementNames() order.
Eigen::Isometry3d& pose(OpticalGeometry& g, std::size_t element)
{
  Eigen::Isometry3d* const members[8] = { &g.source,   &g.mount_x,  &g.mirror_x, &g.mount_y,
                                          &g.mirror_y, &g.window_1, &g.window_2, &g.work_plane };
  return *members[element];
}

std::string validElementNames()
{
  std::string names;
  for (const std::string& n : defectElementNames())
    names += (names.empty() ? "" : ", ") + n;
  return names;
}

std::string lineOf(const std::string& path, const YAML::Node& node)
{
  return path + ":" + std::to_string(node.Mark().line + 1);
}

Eigen::Vector3d readTriple(const YAML::Node& node, const std::string& path, const std::string& key)
{
  if (!node.IsSequence() || node.size() != 3)
    throw InputError(lineOf(path, node) + ": " + key + " must be a list of 3 numbers [a, b, c]");
  Eigen::Vector3d v;
  for (std::size_t k = 0; k < 3; ++k)
  {
    const YAML::Node item = node[k];
    const std::string text = item.IsScalar() ? item.Scalar() : std::string("(not a scalar)");
    double value = 0.0;
    const NumberText parsed = parseNumber(text, value);
    if (parsed != NumberText::Ok)
      throw InputError(lineOf(path, item) + ": " + key + "[" + std::to_string(k) + "] is " +
                       (parsed == NumberText::NotFinite ? "not finite" : "not a number") + " ('" + text + "')");
    v[static_cast<Eigen::Index>(k)] = value;
  }
  return v;
}

std::string fileStem(const std::string& path)
{
  const std::size_t slash = path.find_last_of('/');
  std::string name = slash == std::string::npos ? path : path.substr(slash + 1);
  const std::size_t dot = name.find_last_of('.');
  return dot == std::string::npos || dot == 0 ? name : name.substr(0, dot);
}
}  // namespace

const std::array<std::string, 8>& defectElementNames()
{
  static const std::array<std::string, 8> names = { "laser_source", "galvo_x_mount", "mirror_x",
                                                    "galvo_y_mount", "mirror_y",      "window_1",
                                                    "window_2",     "work_plane" };
  return names;
}

OpticalGeometry applyDefects(const OpticalGeometry& nominal, const DefectSet& defects)
{
  OpticalGeometry g = nominal;
  for (std::size_t k = 0; k < defects.elements.size(); ++k)
  {
    const ElementDefect& d = defects.elements[k];
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

DefectSet loadDefectSet(const std::string& path)
{
  std::ifstream in(path);
  if (!in)
    throw InputError(path + ": cannot open the defect set");
  std::ostringstream text;
  text << in.rdbuf();
  YAML::Node root;
  try
  {
    root = YAML::Load(text.str());
  }
  catch (const YAML::Exception& e)
  {
    throw InputError(path + ":" + std::to_string(e.mark.line + 1) + ": malformed YAML: " + e.msg);
  }

  DefectSet set;
  set.name = fileStem(path);
  if (root.IsNull())
    return set;  // empty file: no defect
  if (!root.IsMap())
    throw InputError(lineOf(path, root) + ": a defect set is a map 'element: {xyz: [..], rpy: [..]}' (elements: " +
                     validElementNames() + ")");
  const std::array<std::string, 8>& names = defectElementNames();
  for (const auto& entry : root)
  {
    const std::string key = entry.first.as<std::string>();
    if (key == "name")
    {
      if (!entry.second.IsScalar())
        throw InputError(lineOf(path, entry.second) + ": name must be a string");
      set.name = entry.second.Scalar();
      continue;
    }
    std::size_t element = names.size();
    for (std::size_t k = 0; k < names.size(); ++k)
    {
      if (names[k] == key)
        element = k;
    }
    if (element == names.size())
      throw InputError(lineOf(path, entry.first) + ": unknown element '" + key + "' (valid: " + validElementNames() +
                       ", and name)");
    const YAML::Node& value = entry.second;
    if (value.IsNull())
      continue;
    if (!value.IsMap())
      throw InputError(lineOf(path, value) + ": " + key + " must be a map {xyz: [x, y, z], rpy: [r, p, y]}");
    for (const auto& field : value)
    {
      const std::string field_key = field.first.as<std::string>();
      if (field_key == "xyz")
        set.elements[element].translation_m = readTriple(field.second, path, key + ".xyz");
      else if (field_key == "rpy")
        set.elements[element].rotation_rad = readTriple(field.second, path, key + ".rpy");
      else
        throw InputError(lineOf(path, field.first) + ": unknown key '" + key + "." + field_key +
                         "' (valid: xyz [m], rpy [rad])");
    }
  }
  return set;
}

DefectSet typicalDefectSet()
{
  // OPT table 2 [mm, mrad] written as [m, rad]; the axis mapping is in the file comment.
  DefectSet set;
  set.name = "typical";
  auto put = [&set](std::size_t k, const Eigen::Vector3d& xyz_m, const Eigen::Vector3d& rpy_rad) {
    set.elements[k].translation_m = xyz_m;
    set.elements[k].rotation_rad = rpy_rad;
  };
  // laser_source: OPT y z b c = -0.063 -0.085 mm, -0.069 -0.065 mrad
  put(0, { 0.0, -0.063e-3, -0.085e-3 }, { 0.0, -0.069e-3, -0.065e-3 });
  // galvo_x_mount: OPT y z = -0.040 -0.023 mm -> our x y; a b c = 0.030 0.063 0.053 mrad -> yaw roll pitch
  put(1, { -0.040e-3, -0.023e-3, 0.0 }, { 0.063e-3, 0.053e-3, 0.030e-3 });
  // mirror_x: OPT z = -0.025 mm -> our x; a b = -0.062 0.029 mrad -> pitch yaw
  put(2, { -0.025e-3, 0.0, 0.0 }, { 0.0, -0.062e-3, 0.029e-3 });
  // galvo_y_mount: OPT y z = -0.099 -0.043 mm -> our x y; a b c = -0.028 0.018 -0.035 mrad -> yaw roll pitch
  put(3, { -0.099e-3, -0.043e-3, 0.0 }, { 0.018e-3, -0.035e-3, -0.028e-3 });
  // mirror_y: OPT z = 0.000 mm -> our x; a b = -0.075 0.047 mrad -> pitch yaw
  put(4, { 0.0, 0.0, 0.0 }, { 0.0, -0.075e-3, 0.047e-3 });
  // window_1: OPT a b = -0.069 -0.013 mrad
  put(5, { 0.0, 0.0, 0.0 }, { -0.069e-3, -0.013e-3, 0.0 });
  // window_2: OPT a b = 0.066 -0.028 mrad
  put(6, { 0.0, 0.0, 0.0 }, { 0.066e-3, -0.028e-3, 0.0 });
  // work_plane: OPT x y z = -0.085 0.011 -0.045 mm, a b c = -0.074 0.040 -0.003 mrad
  put(7, { -0.085e-3, 0.011e-3, -0.045e-3 }, { -0.074e-3, 0.040e-3, -0.003e-3 });
  return set;
}
}  // namespace scanhead
