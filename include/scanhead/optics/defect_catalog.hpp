/// \file defect_catalog.hpp
/// \brief The 30 assembly defects of the optical chain (SPEC §4, OPT table 1): the OPT convention
/// (mm, mrad, per element in its own OPT frame), its mapping onto the 8 defect joints of our URDF,
/// defect sets, their application to a geometry, OPT's table 2 and seeded random sets.
///
/// Element ↔ defect joint ↔ OpticalGeometry member (urdf/scanhead.urdf, optical_geometry_urdf.cpp):
///   source     → laser_source_defect_joint  → source    (beam along our +x)
///   axis_x     → galvo_x_mount_defect_joint → mount_x   (rotor axis our +z)
///   mirror_x   → mirror_x_defect_joint      → mirror_x  (in the rotor frame; our +x = surface normal)
///   axis_y, mirror_y → galvo_y_mount_defect_joint, mirror_y_defect_joint → mount_y, mirror_y
///   window_1, window_2 → window_*_defect_joint → window_1, window_2 (our +z = face normal)
///   work_plane → work_plane_defect_joint    → work_plane (spots in this frame)
/// Each member is the product of the URDF fixed-joint origins down to the defect link, the last
/// being `<element>_defect_joint` (identity in the nominal URDF), so right-multiplying it by D is
/// the same as writing D into that joint's origin (mount_* also carry the galvo joint origin after
/// the defect joint; it is identity in our URDF).
///
/// OPT (seeds/001_6db5768eacf0c62f.txt, "Tableau 1") lists per element only the components that
/// act on the spot, in its own frames: the beam along OPT x for the source, the rotation axis along
/// OPT x for the galvo axes (no x translation), the normal along OPT z for mirrors, windows and the
/// plane. Our frames put the rotation axis on z and the mirror normal on x, so each value goes to
/// the axis of our frame that plays the same role, by a cyclic relabelling of the axes (which keeps
/// rotations right-handed, so no sign changes):
///
/// | OPT component            | our defect joint          | our component      | sign |
/// |--------------------------|---------------------------|--------------------|------|
/// | source.y z               | laser_source              | x y z: y z         | +    |
/// | source.b c               | laser_source              | pitch yaw          | +    |
/// | axis_x.y z (⊥ axis)      | galvo_x_mount             | x y                | +    |
/// | axis_x.a (about axis)    | galvo_x_mount             | yaw (about z)      | +    |
/// | axis_x.b c (axis tilts)  | galvo_x_mount             | roll pitch         | +    |
/// | mirror_x.z (normal)      | mirror_x                  | x                  | +    |
/// | mirror_x.a b (tilts)     | mirror_x                  | pitch yaw          | +    |
/// | axis_y.*, mirror_y.*     | galvo_y_mount, mirror_y   | as axis_x, mirror_x| +    |
/// | window_k.a b (tilts)     | window_k                  | roll pitch         | +    |
/// | work_plane.x y z a b c   | work_plane                | x y z roll pitch yaw | +  |
///
/// i.e. galvo mounts: OPT (x, y, z) → our (z, x, y); mirrors: OPT (x, y, z) → our (y, z, x);
/// the others as written. Placed literally instead, a mirror's z translation and a rotation would
/// slide or spin the mirror in its own plane and do nothing. Values: mm → m and mrad → rad (÷ 1000).
/// The rotation is composed as the URDF does,
/// \f[ D = \mathrm{Trans}(t)\, R_z(\mathrm{yaw})\, R_y(\mathrm{pitch})\, R_x(\mathrm{roll}) \f]
/// about OUR axes (URDF rpy: fixed-axis x, then y, then z); for the galvo mounts this is OPT's
/// extrinsic x-y-z order with the axes relabelled only up to second order (≤ 1e-8 rad for
/// 0.1 mrad defects, ~10 nm on the plane).
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
  const char* element;  ///< source, axis_x, mirror_x, axis_y, mirror_y, window_1, window_2, work_plane
  char component;       ///< x, y, z (translation, mm) or a, b, c (rotation about x, y, z, mrad)
  bool rotation() const { return component == 'a' || component == 'b' || component == 'c'; }
};

/// \brief The 30 defects in OPT table 2's order: source y z b c; axis_x y z a b c; mirror_x z a b;
/// axis_y y z a b c; mirror_y z a b; window_1 a b; window_2 a b; work_plane x y z a b c.
const std::array<DefectComponent, kDefectCount>& defectComponents();

/// \brief The 8 element keys of defect set files (source, axis_x, mirror_x, axis_y, mirror_y,
/// window_1, window_2, work_plane), in the order of defectJointElements().
const std::array<const char*, 8>& defectElements();

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
/// our frame that plays the same role (the table above: OPT puts the galvo axis on x and the
/// mirror normal on z, our URDF puts them on z and x). A -0 comes out as +0.
std::array<ElementDefect, 8> elementDefects(const DefectSet& set);

/// \brief Each defect frame pose P becomes P·D, D = Trans(t)·Rot_rpy(r) of elementDefects()
/// (the same as writing D into the URDF's defect joint origins). Elements without a defect keep
/// their pose bit for bit.
OpticalGeometry applyDefects(const OpticalGeometry& nominal, const DefectSet& set);

/// \brief OPT table 2, the paper's "defective machine" (SPEC §4); config/defects/opt_table2.yaml
/// holds the same numbers.
DefectSet optTable2DefectSet();

/// \brief Every value drawn uniformly in ±bound_mm (translations) or ±bound_mrad (rotations):
/// \f[ v_k = B_k\,(2u_k - 1), \qquad u_k \in [0, 1) \f]
/// with u_k the k-th SplitMix64(seed).uniformClosedOpen() (random.hpp), k in defectComponents()
/// order; 2u − 1 is exact, so one rounding, and the same values on every platform. OPT drew its
/// table 2 within ±0.1 mm / ±0.1 mrad. Named "random_seed<N>", plus "_mm<B>_mrad<B>" when the
/// bounds are not 0.1.
/// \throws ConfigError if a bound is negative or not finite
DefectSet randomDefectSet(std::uint64_t seed, double bound_mm = 0.1, double bound_mrad = 0.1);
}  // namespace scanhead
