/// \file optical_model.hpp
/// \brief Direct (ray trace) and inverse (Newton) geometric models of the two-mirror head.
///
/// Geometry comes from the URDF (nominal + defect frames of the eight elements); the beam is
/// reflected on both mirrors (d' = d - 2(d.n)n, surfaces offset from their axes) and refracted
/// through both faces of both windows (vector Snell law), then intersected with the work plane.
#pragma once

#include <Eigen/Geometry>
#include <cstddef>
#include <memory>
#include <string>
#include <vector>

#include "scanhead/optics/optics_config.hpp"

namespace scanhead
{
namespace detail
{
struct TraceSurfaces;  ///< the trace's constant surfaces as plain numbers (optical_model.cpp)
}

/// \brief Poses, in the scanhead_base frame, of the frames the ray trace uses.
///
/// Conventions (see urdf/scanhead.urdf): the source emits along the +x axis of source_defect;
/// each galvo rotor turns about the +z axis of its mount_defect frame by the joint angle; a
/// mirror surface passes through the origin of mirror_*_defect with the +x axis as normal; a
/// window's first face is the z = 0 plane of window_*_defect, the second at z = -thickness;
/// the work plane is the z = 0 plane of work_plane_defect, spots are given in that frame.
struct OpticalGeometry
{
  Eigen::Isometry3d source = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d mount_x = Eigen::Isometry3d::Identity();   ///< galvo X mount_defect frame
  Eigen::Isometry3d mirror_x = Eigen::Isometry3d::Identity();  ///< mirror_x_defect in the rotor frame
  Eigen::Isometry3d mount_y = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d mirror_y = Eigen::Isometry3d::Identity();  ///< mirror_y_defect in the rotor frame
  Eigen::Isometry3d window_1 = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d window_2 = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d work_plane = Eigen::Isometry3d::Identity();
  double joint_lower_rad = -0.1745;  ///< mechanical range of both galvos (URDF joint limits)
  double joint_upper_rad = 0.1745;
};

/// \brief Geometry read from a URDF string with urdfdom.
///
/// Each pose is the product of the fixed-joint origins from `scanhead_base` down to the link
/// (`mount_*` also includes the origin of the revolute joint `galvo_*`, identity in our URDF;
/// `mirror_*` is the product from the rotor link `galvo_*`'s child down to `mirror_*_defect`).
/// The joint limits are the intersection of those of `galvo_x` and `galvo_y`.
/// \throws InputError naming \p source_name and the missing link/joint, a galvo joint that is not
///         revolute about (0, 0, 1), or a non-fixed joint on a path that must be rigid
OpticalGeometry geometryFromUrdf(const std::string& urdf_xml, const std::string& source_name);

/// \brief The text of a URDF file. \throws InputError naming the file if it cannot be read
std::string readUrdfFile(const std::string& path);

/// \brief Reads a URDF file and calls geometryFromUrdf. \throws InputError
OpticalGeometry geometryFromUrdfFile(const std::string& path);

class OpticalModel
{
public:
  struct Ray
  {
    Eigen::Vector2d spot;       ///< intersection with the work plane, work-plane frame [m]
    Eigen::Vector3d direction;  ///< unit beam direction at the plane, work-plane frame
  };

  /// \pre config.validate() passes (not re-checked here).
  OpticalModel(const OpticalGeometry& geometry, const OpticsConfig& config);

  /// \brief Direct model h(θx, θy) (SPEC §4, OPT MGD): a single ray traced from the source.
  ///
  /// Mirror k at angle q_k: frame \f[ T_{m,k}(q_k) = T_{mount,k}\,R_z(q_k)\,T_{mirror,k} \f];
  /// reflection \f[ d' = d - 2(d\cdot n)\,n \f]; at each window face (unit normal N facing the
  /// ray, \f$\eta = n_1/n_2\f$ entering, \f$n_2/n_1\f$ leaving, \f$c = -d\cdot N\f$)
  /// \f[ d' = \eta\,d + \big(\eta c - \sqrt{1 - \eta^2 (1 - c^2)}\big)\,N. \f]
  /// The faces of a window are parallel, so the second refraction restores d exactly: the ray
  /// runs \f$e_v / \cos r\f$ along d' inside the glass (\f$\cos r = -d'\cdot N\f$) and leaves along d.
  /// \param[in] q mechanical angles [rad] (galvo_x, galvo_y)
  /// \throws NumericalError if the ray misses a surface (parallel to it or going away from it)
  ///         or is totally reflected inside a window
  Ray trace(const Eigen::Vector2d& q) const;
  Eigen::Vector2d spot(const Eigen::Vector2d& q) const { return trace(q).spot; }
  /// \brief Where the beam of trace(\p q) is, in scanhead_base [m]: the source, its hits on mirror X and mirror Y,
  /// where it leaves window 1 and window 2, and the spot on the work plane (6 points: what rviz draws as the beam).
  /// \throws NumericalError as trace()
  std::vector<Eigen::Vector3d> beamPoints(const Eigen::Vector2d& q) const;

  /// \brief trace() of \p n rays at once, in structure-of-arrays form (the same operations in the
  /// same order, 4 rays in the lanes of a vector; an AVX2 clone where the CPU has it, without FMA):
  /// the results are bit-identical to trace() ray by ray.
  /// \param[in]  n          number of rays
  /// \param[in]  q_x, q_y   mechanical angles [rad], n each
  /// \param[out] spot_x, spot_y  spots [m], work-plane frame, n each
  /// \param[out] dir_x, dir_y, dir_z  unit beam directions at the plane, n each; all three null
  ///             to skip them
  /// \return the number of rays that failed (where trace() throws): their outputs are NaN
  ///         (call trace() on one of them for the error). Does not throw.
  std::size_t traceBlock(std::size_t n, const double* q_x, const double* q_y, double* spot_x, double* spot_y,
                         double* dir_x = nullptr, double* dir_y = nullptr, double* dir_z = nullptr) const;

  /// \brief Jacobian d(spot)/dq [m/rad], exact (forward-mode derivatives propagated through
  /// every intersection, reflection and refraction of the ray trace; costs about 2 traces).
  Eigen::Matrix2d jacobian(const Eigen::Vector2d& q) const;

  /// \brief Inverse model by Newton-Raphson from \p q_guess (SPEC §4, OPT MGI):
  /// \f[ q_{k+1} = q_k + J(q_k)^{-1}\,(x^* - h(q_k)) \f] until \f$|x^* - h(q_k)| \le\f$
  /// newton_tolerance_m, at most newton_max_iterations steps. J is re-evaluated only when q has
  /// moved more than 1e-3 rad from where it was last evaluated (simplified Newton; contraction
  /// <~1e-3 per step), so a warm start near the answer costs one Jacobian and a few plain traces.
  /// \throws NumericalError ("spot (x, y) mm not reachable ...") if it does not converge, the ray
  ///         misses on the way, or the solution lies outside the joint limits
  Eigen::Vector2d inverse(const Eigen::Vector2d& spot, const Eigen::Vector2d& q_guess) const;
  Eigen::Vector2d inverse(const Eigen::Vector2d& spot) const { return inverse(spot, Eigen::Vector2d::Zero()); }

  /// \brief Pose of a mirror surface frame in scanhead_base at joint angle \p angle_rad.
  Eigen::Isometry3d mirrorXPose(double angle_rad) const;
  Eigen::Isometry3d mirrorYPose(double angle_rad) const;

  const OpticalGeometry& geometry() const { return geometry_; }
  const OpticsConfig& config() const { return config_; }

private:
  /// Mirror normal and surface point in the base frame at angle q:
  /// n(q) = cos q·n_c + sin q·n_s + n_0, likewise p(q) (R_z(q) expanded, precomputed).
  struct MirrorTerms
  {
    Eigen::Vector3d n_c, n_s, n_0;
    Eigen::Vector3d p_c, p_s, p_0;
  };
  /// kRecord: append where the ray is after each surface to *points (beamPoints)
  template <bool kWithJacobian, bool kRecord = false>
  Ray traceImpl(const Eigen::Vector2d& q, Eigen::Matrix2d* jacobian, std::vector<Eigen::Vector3d>* points) const;
  Ray traceWithJacobian(const Eigen::Vector2d& q, Eigen::Matrix2d& jacobian) const;

  OpticalGeometry geometry_;
  OpticsConfig config_;
  Eigen::Vector3d source_point_, source_direction_;
  MirrorTerms mirror_x_terms_, mirror_y_terms_;
  Eigen::Vector3d window_1_point_, window_1_normal_;  ///< first face of window 1 (base frame)
  Eigen::Vector3d window_2_point_, window_2_normal_;
  Eigen::Vector3d plane_point_, plane_normal_;
  Eigen::Matrix3d plane_rotation_t_;                       ///< base -> work-plane rotation
  double eta_ = 1.0;                                       ///< n_gas / n_window
  std::shared_ptr<const detail::TraceSurfaces> surfaces_;  ///< the same, for the plain trace kernel
};
}  // namespace scanhead
