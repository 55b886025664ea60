/// \file job_placement.hpp
/// \brief A job in the build plate's frame placed on the scan field: rotated about the plate origin, then offset.
///
/// Build files from slicers and machines are in plate coordinates (an ORNL Peregrine layer lies around
/// x = 200 mm, y = 20 mm); a machine maps its plate onto the scan field by a rigid motion. With
/// cam.rotation_deg = θ and cam.offset_m = o, a point p of the file lands at
///   p_field = R(θ)·p + o,   R(θ) = [cos θ, −sin θ; sin θ, cos θ]   (counter-clockwise, about the plate origin);
/// with cam.centre the translation is chosen so that the centre of the rotated job's bounding box lands on o:
///   p_field = R(θ)·p − c + o,   c = centre of the bounding box of {R(θ)·p} over every point of the file.
/// The bounding box is that of the whole file (every layer of a layered file), so the layers of a build keep
/// their relative position. The placement applied is kept with the job (job.yaml, metrics.yaml).
#pragma once

#include <Eigen/Core>
#include <string>

namespace scanhead
{
struct Job;
struct CamConfig;

/// \brief The rigid motion from the file's frame to the field's: p_field = R(rotation_deg)·p + offset_m.
struct JobPlacement
{
  double rotation_deg = 0.0;
  Eigen::Vector2d offset_m = Eigen::Vector2d::Zero();  ///< the translation applied after the rotation [m]
  bool centred = false;                                ///< offset_m came from cam.centre

  bool identity() const { return rotation_deg == 0.0 && offset_m.isZero(); }
  /// \brief Whether the job was placed at all (a centring that happened to move nothing counts): what job.yaml and
  /// metrics.yaml record.
  bool placed() const { return !identity() || centred; }
  /// \brief One YAML flow map: {rotation_deg: θ, offset_m: [x, y], centred: true|false}.
  std::string yaml() const;
};

/// \brief R(\p degrees) (exact for multiples of 90°).
Eigen::Matrix2d placementRotation(double degrees);

/// \brief Bounding box of every point of \p job (marks, jumps, dwells), after the rotation by \p rotation_deg.
/// \returns false for a job without points
bool rotatedBoundingBox(const Job& job, double rotation_deg, Eigen::Vector2d& lo, Eigen::Vector2d& hi);

/// \brief The placement the cam settings ask for \p job; cam.centre uses the bounding box of the whole file the
/// job was read from (job.file, surveyed by the layered-file readers), else that of \p job.
/// \throws InputError if cam.centre is set and the file has no point.
JobPlacement placementFor(const CamConfig& cam, const Job& job);

/// \brief Moves every point of \p job by \p placement and composes it with the job's own (job.placement).
void placeJob(Job& job, const JobPlacement& placement);
}  // namespace scanhead
