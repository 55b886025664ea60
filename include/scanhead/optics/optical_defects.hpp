/// \file optical_defects.hpp
/// \brief The 30 assembly defects of the optical chain (SPEC §4, OPT table 2): defect sets in
/// the OPT convention (mm, mrad, per element in its own OPT frame), their mapping onto the defect
/// joints of our URDF, random sets, and the URDF of a defective machine.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <cstdint>
#include <string>

#include "scanhead/optics/optical_model.hpp"

namespace scanhead
{
/// \brief Displacement of one element's defect frame relative to its nominal frame, in OUR frames
/// (the origin of the URDF joint `<element>_defect_joint`).
struct ElementDefect
{
  Eigen::Vector3d translation_m = Eigen::Vector3d::Zero();  ///< [m], in the nominal frame
  Eigen::Vector3d rotation_rad = Eigen::Vector3d::Zero();   ///< roll, pitch, yaw [rad] (URDF rpy)
};

constexpr std::size_t kDefectCount = 30;

/// \brief One of the 30 defects: element (YAML key) and component in the OPT convention.
struct DefectComponent
{
  const char* element;    ///< source, axis_x, mirror_x, axis_y, mirror_y, window_1, window_2, work_plane
  char component;         ///< x, y, z (translation, mm) or a, b, c (rotation about x, y, z, mrad)
  bool rotation() const { return component == 'a' || component == 'b' || component == 'c'; }
};

/// \brief The 30 defects in OPT table 2's order: source y z b c; axis_x y z a b c; mirror_x z a b;
/// axis_y y z a b c; mirror_y z a b; window_1 a b; window_2 a b; work_plane x y z a b c.
const std::array<DefectComponent, kDefectCount>& defectComponents();

/// \brief "source.y", "axis_x.a", ... (for reports). \throws std::out_of_range if index >= 30
std::string defectLabel(std::size_t index);

/// \brief The index of "element.component". \throws InputError listing the 30 labels
std::size_t defectIndex(const std::string& label);

/// \brief A defect set: the 30 values in the OPT convention.
struct DefectSet
{
  std::string name = "nominal";
  std::array<double, kDefectCount> values{};  ///< mm for x, y, z; mrad for a, b, c

  bool isNominal() const;  ///< all zero
};

/// \brief Our URDF has 8 defect joints: laser_source, galvo_x_mount, mirror_x, galvo_y_mount,
/// mirror_y, window_1, window_2, work_plane (the element order of elementDefects()).
const std::array<std::string, 8>& defectJointElements();

/// \brief The set as the origins of our 8 defect joints (SI), each OPT component on the axis of
/// our frame that plays the same role (optical_defects.cpp: OPT puts the galvo axis on x and the
/// mirror normal on z, our URDF puts them on z and x).
std::array<ElementDefect, 8> elementDefects(const DefectSet& set);

/// \brief Each defect frame pose P becomes P·D, D = Trans(t)·Rot_rpy(r) of elementDefects()
/// (the same as writing D into the URDF's defect joint origins).
OpticalGeometry applyDefects(const OpticalGeometry& nominal, const DefectSet& set);

/// \brief Reads a defect set file: a YAML map element → {component: value}, mm and mrad, e.g.
/// `source: {y: -0.063, z: -0.085, b: -0.069, c: -0.065}`; missing entries are zero, an optional
/// top-level `name:`; any other key (an unknown element, or a component that is not one of the 30
/// defects, e.g. mirror_x.x) is an error. \throws InputError naming the file, line and key, and
/// listing the allowed ones
DefectSet loadDefectSet(const std::string& path);

/// \brief The set as a defect set file (full precision, all 30 entries).
std::string defectSetToYaml(const DefectSet& set);

/// \brief OPT table 2, the paper's "defective machine" (SPEC §4).
DefectSet optTable2DefectSet();

/// \brief Every value drawn uniformly in ±bound_mm (translations) or ±bound_mrad (rotations),
/// from a 64-bit seed with a portable generator (same values on every platform); OPT drew its
/// table 2 within ±0.1 mm / ±0.1 mrad.
DefectSet randomDefectSet(std::uint64_t seed, double bound_mm = 0.1, double bound_mrad = 0.1);

/// \brief "nominal" | "opt_table2" | "random:seed=N[,mm=B][,mrad=B]" | a defect set file (.yaml).
/// \throws InputError (bad file or spec: names it and lists the forms)
DefectSet defectSetByName(const std::string& spec);

/// \brief \p nominal_urdf with the origins of the 8 `<element>_defect_joint` joints replaced by
/// elementDefects(set) (full precision); everything else unchanged. A nominal set returns the text
/// as it is (a URDF that already carries defects in its joints keeps them).
/// \throws InputError naming \p source_name if a defect joint is missing
std::string urdfWithDefects(const std::string& nominal_urdf, const DefectSet& set, const std::string& source_name);
}  // namespace scanhead
