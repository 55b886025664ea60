/// \file nominal_closed_form.cpp
/// \brief Closed-form direct model of the nominal head (SPEC §4, OPT eqs. 2–6), derived for the
/// layout of urdf/scanhead.urdf; a cross-check of the ray trace (test_nominal_closed_form.cpp:
/// max |closed form − trace| = 9.0e-16 m over a 41 × 41 grid of the joint range ±0.1745 rad,
/// which contains the field).
///
/// Layout (urdf/scanhead.urdf header; base frame, z up, spot in the work-plane frame):
///   source S = (S_x, S_y, S_z), beam along +x;
///   galvo X axis along base −z through A_x = (A_x.x, A_x.y, ·): the rotor turns by −θx about +z,
///     so the mirror X normal is n_X = (−cos β, sin β, 0), β = θx + π/4;
///   galvo Y axis along base +x through A_y = (·, A_y.y, A_y.z): n_Y = (0, −cos γ, −sin γ),
///     γ = θy + π/4;
///   each mirror surface is the plane n·(p − A) = e_m (e_m from the mirror frame in its rotor
///     frame: the signed distance of the surface from the axis along the normal, 2.5 mm);
///   two horizontal windows of thickness e_v, indices n1 (gas), n2 (glass); work plane z = z_p.
///
/// Derivation (every step an intersection with a plane or a reflection, solved by hand):
///  1. Mirror X: the ray S + t·e_x meets n_X·(p − A_x) = e_m at
///       P1 = (x1, S_y, S_z),  x1 = A_x.x − (e_m + u·sin β)/cos β,  u = A_x.y − S_y;
///     d1 = e_x − 2(e_x·n_X) n_X = (−cos 2β, sin 2β, 0) = (sin 2θx, cos 2θx, 0).
///  2. Mirror Y: P1 + t·d1 meets n_Y·(p − A_y) = e_m at t = K1 / cos 2θx, with
///       K1 = (v_y cos γ + v_z sin γ − e_m) / cos γ,  v_y = A_y.y − S_y,  v_z = A_y.z − S_z
///     (K1: the y travel from mirror X to mirror Y, independent of θx since mirror Y contains the
///     x direction; = d = 20 mm at θy = 0), so P2 = (x1 + K1 tan 2θx, S_y + K1, S_z);
///     d2 = d1 − 2(d1·n_Y) n_Y = (sin 2θx, cos 2θx sin 2θy, −cos 2θx cos 2θy).
///  3. Windows: a plate of thickness e crossed with incidence cos i = cos 2θx cos 2θy changes the
///     horizontal travel over its thickness from e·d_h/cos i to e·d_h/√(n2²/n1² − 1 + cos² i)
///     (Snell: the tangential part of n·d is kept); hence
///       K3 = √(cos² 2θx cos² 2θy − 1 + n2²/n1²)
///     and the two windows (2e_v of glass in total, wherever they are) replace 2e_v of the descent.
///  4. Plane: from height H = S_z − z_p, with K2 = H − 2e_v the gas part of the descent,
///       x = x1 + K1 tan 2θx + K2 tan 2θx / cos 2θy + 2e_v sin 2θx / K3 − p_x
///       y = S_y + K1 + K2 tan 2θy + 2e_v cos 2θx sin 2θy / K3 − p_y
///     ((p_x, p_y, z_p) = work-plane origin in the base frame; the nominal plane is horizontal).
///
/// OPT's transcribed eqs. 2–6 (SPEC §4) against ours. OPT's frames differ from ours (its galvo
/// axes on x, mirror normals on z, per defect_catalog.hpp), but its nominal parameters are
/// positions and angles that can be given values for our head. With
///   X_p = p_x − S_x, Y_p = p_y − S_y, Z_p = z_p − S_z = −H  (plane origin in the source frame),
///   Y_ay0 = v_y, Z_ay0 = v_z, A_ay0 = 3π/4              (axis Y in the source frame),
///   X_ax0 = A_x.x − S_x, Y_ax0 = S_y − A_x.y = −u, A_ax0 = π/4, B_ax0 = π/2,
/// and θx, θy, x, y with our signs, the transcription reproduces our head exactly (the test
/// OptTranscriptionWithOurParametersMatchesTrace: 9.0e-16 m). Term by term:
///   eq. 2, K1_OPT = (e_m + Z_ay0 cos(A_ay0 + θy) − Y_ay0 sin(A_ay0 + θy)) / cos(A_ay0 − B_ax0 + θy)
///     = (e_m − v_z sin γ − v_y cos γ)/cos γ = −K1: OPT's K1 is minus our mirror-to-mirror
///     travel (−20 mm at θ = 0); −K1_OPT·sin B_ax0 in eq. 6 is our +K1, −K1_OPT tan 2θx in
///     eq. 5 our +K1 tan 2θx, so these signs are consistent.
///   eq. 3, K2_OPT = Z_p + 2e_v − K1_OPT cos B_ax0 = −(H − 2e_v) = −K2 (B_ax0 = π/2: our beam
///     between the mirrors is horizontal, so the height of mirror Y does not depend on K1);
///     −K2_OPT tan 2θy (eq. 6) and −K2_OPT tan 2θx / cos 2θy (eq. 5) are our descent terms.
///     "2e_v" is right: two windows of e_v each; its sign too (the glass shortens the gas path).
///   eq. 4, K3: identical (it needs n2/n1, not n1/n2, and the product cos² 2θx cos² 2θy).
///   eq. 5, 2e_v sin 2θx / K3 and eq. 6, 2e_v cos 2θx sin 2θy / K3: identical to ours.
///   eq. 5, X_ax0 + (e_m − Y_ax0 cos(−A_ax0 + θx) sin B_ax0) / sin(−A_ax0 + θx): with
///     A_ax0 = π/4, sin(θx − π/4) = −cos β, cos(θx − π/4) = sin β, it is our x1 − S_x provided
///     Y_ax0 = S_y − A_x.y, i.e. the offset of the SOURCE from the axis, whereas Y_ay0, Z_ay0
///     (eq. 2) are offsets of the axis from the source. Read with the same convention as the
///     other positions (Y_ax0 = A_x.y − S_y), eq. 5 is off by 2u·tan β = −√2·e_m·tan(θx + π/4):
///     3.5 mm at the centre, 4.5 mm at the field's edge, 5.0 mm at the joint limit (test). So
///     either OPT defines the ax0 translation the other way round, or the sign before Y_ax0 is a
///     transcription error; the sin B_ax0 factor on the Y_ax0 term alone (not on e_m) cannot be
///     checked with our head (B_ax0 = π/2, sin = 1).
/// Conclusion: eqs. 2–4 and 6 are right as transcribed, eq. 5 holds up to that one sign
/// convention; no factor 2 or index ratio is wrong.
///
/// Domain: |θ| < π/4 keeps every cosine positive (the joints stop at 0.1745 rad).
#include "scanhead/optics/nominal_closed_form.hpp"

#include <cmath>

namespace scanhead
{
namespace
{
/// Signed distance [m] from a galvo axis (the z axis of the rotor frame) to the mirror surface
/// through \p mirror's origin with normal \p mirror's +x: e_m = n·p.
double surfaceOffset(const Eigen::Isometry3d& mirror)
{
  return mirror.linear().col(0).dot(mirror.translation());
}
}  // namespace

Eigen::Vector2d closedFormSpot(const OpticalGeometry& nominal, const OpticsConfig& config, const Eigen::Vector2d& q)
{
  constexpr double kQuarterPi = 0.78539816339744830962;
  const Eigen::Vector3d s = nominal.source.translation();
  const Eigen::Vector3d ax = nominal.mount_x.translation();
  const Eigen::Vector3d ay = nominal.mount_y.translation();
  const Eigen::Vector3d plane = nominal.work_plane.translation();
  const double em_x = surfaceOffset(nominal.mirror_x);
  const double em_y = surfaceOffset(nominal.mirror_y);
  const double ev = config.window_thickness_m;
  const double index_ratio = config.n_window / config.n_gas;  // n2 / n1

  const double beta = q.x() + kQuarterPi;
  const double gamma = q.y() + kQuarterPi;
  const double c2x = std::cos(2.0 * q.x());
  const double s2x = std::sin(2.0 * q.x());
  const double c2y = std::cos(2.0 * q.y());
  const double s2y = std::sin(2.0 * q.y());

  // 1. mirror X hit point (x only: y and z are the source's)
  const double u = ax.y() - s.y();
  const double x1 = ax.x() - (em_x + u * std::sin(beta)) / std::cos(beta);
  // 2. y travel from mirror X to mirror Y
  const double vy = ay.y() - s.y();
  const double vz = ay.z() - s.z();
  const double k1 = (vy * std::cos(gamma) + vz * std::sin(gamma) - em_y) / std::cos(gamma);
  // 3. windows
  const double k3 = std::sqrt(c2x * c2x * c2y * c2y - 1.0 + index_ratio * index_ratio);
  // 4. descent to the plane
  const double k2 = (s.z() - plane.z()) - 2.0 * ev;
  const double t2x = s2x / c2x;
  const double x = x1 + k1 * t2x + k2 * t2x / c2y + 2.0 * ev * s2x / k3 - plane.x();
  const double y = s.y() + k1 + k2 * s2y / c2y + 2.0 * ev * c2x * s2y / k3 - plane.y();
  return Eigen::Vector2d(x, y);
}
}  // namespace scanhead
