/// \file optical_defects.hpp
/// \brief Assembly defects of the eight optical elements as small rigid displacements of their
/// defect frames (SPEC §4, OPT): read from a YAML defect set, applied to an OpticalGeometry.
#pragma once

#include <Eigen/Core>
#include <array>
#include <string>

#include "scanhead/core/optical_model.hpp"

namespace scanhead
{
/// \brief Displacement of one element's defect frame relative to its nominal frame.
struct ElementDefect
{
  Eigen::Vector3d translation_m = Eigen::Vector3d::Zero();  ///< [m], in the nominal frame
  Eigen::Vector3d rotation_rad = Eigen::Vector3d::Zero();   ///< roll, pitch, yaw [rad] (URDF rpy)
};

/// \brief One ElementDefect per element, in the order of defectElementNames().
struct DefectSet
{
  std::string name = "nominal";
  std::array<ElementDefect, 8> elements{};
};

/// \brief laser_source, galvo_x_mount, mirror_x, galvo_y_mount, mirror_y, window_1, window_2, work_plane.
const std::array<std::string, 8>& defectElementNames();

/// \brief Each defect frame pose P becomes P·D with D = Trans(t)·Rot_rpy(r) (the URDF's
/// `<element>_defect_joint` origin, identity in the nominal URDF).
OpticalGeometry applyDefects(const OpticalGeometry& nominal, const DefectSet& defects);

/// \brief Reads a defect set: a YAML map `element: {xyz: [x, y, z], rpy: [r, p, y]}` (metres,
/// radians; omitted elements and keys are zero). \throws InputError naming the file and the key
DefectSet loadDefectSet(const std::string& path);

/// \brief A typical assembly: every element displaced by tolerance-class amounts (values and
/// their source in optical_defects.cpp).
DefectSet typicalDefectSet();
}  // namespace scanhead
