/// \file nominal_closed_form.hpp
/// \brief The direct model of the nominal head in closed form (SPEC §4, OPT eqs. 2–6), an
/// independent cross-check of the ray trace (OpticalModel::trace).
#pragma once

#include <Eigen/Core>

#include "scanhead/optics/optical_model.hpp"

namespace scanhead
{
/// \brief Spot (x, y) on the work plane [m] of the nominal machine \p nominal at mechanical
/// angles \p q [rad], from closed-form expressions (no ray marching).
///
/// \details Derived for the layout of urdf/scanhead.urdf; a cross-check of the ray trace
/// (test_nominal_closed_form.cpp: max |closed form − trace| = 9.0e-16 m over a 41 × 41 grid of
/// the joint range ±0.1745 rad, which contains the field).
///
/// \par Layout
/// (urdf/scanhead.urdf header; base frame, z up, spot in the work-plane frame)
/// - source \f$S = (S_x, S_y, S_z)\f$, beam along +x;
/// - galvo X axis along base −z through \f$A_x = (A_{x,x}, A_{x,y}, \cdot)\f$: the rotor turns by
///   \f$-\theta_x\f$ about +z, so the mirror X normal is \f$n_X = (-\cos\beta, \sin\beta, 0)\f$,
///   \f$\beta = \theta_x + \pi/4\f$;
/// - galvo Y axis along base +x through \f$A_y = (\cdot, A_{y,y}, A_{y,z})\f$:
///   \f$n_Y = (0, -\cos\gamma, -\sin\gamma)\f$, \f$\gamma = \theta_y + \pi/4\f$;
/// - each mirror surface is the plane \f$n \cdot (p - A) = e_m\f$ (\f$e_m\f$ from the mirror frame
///   in its rotor frame: the signed distance of the surface from the axis along the normal,
///   2.5 mm);
/// - two horizontal windows of thickness \f$e_v\f$, indices \f$n_1\f$ (gas), \f$n_2\f$ (glass);
///   work plane \f$z = z_p\f$.
///
/// \par Derivation
/// Every step is an intersection with a plane or a reflection, solved by hand.
/// 1. Mirror X: the ray \f$S + t\,e_x\f$ meets \f$n_X \cdot (p - A_x) = e_m\f$ at
///    \f[ P_1 = (x_1, S_y, S_z), \quad x_1 = A_{x,x} - \frac{e_m + u \sin\beta}{\cos\beta},
///        \quad u = A_{x,y} - S_y, \f]
///    \f[ d_1 = e_x - 2 (e_x \cdot n_X)\, n_X = (-\cos 2\beta, \sin 2\beta, 0)
///            = (\sin 2\theta_x, \cos 2\theta_x, 0). \f]
/// 2. Mirror Y: \f$P_1 + t\,d_1\f$ meets \f$n_Y \cdot (p - A_y) = e_m\f$ at
///    \f$t = K_1 / \cos 2\theta_x\f$, with
///    \f[ K_1 = \frac{v_y \cos\gamma + v_z \sin\gamma - e_m}{\cos\gamma}, \quad v_y = A_{y,y} - S_y,
///        \quad v_z = A_{y,z} - S_z \f]
///    (\f$K_1\f$: the y travel from mirror X to mirror Y, independent of \f$\theta_x\f$ since
///    mirror Y contains the x direction; = d = 20 mm at \f$\theta_y = 0\f$), so
///    \f$P_2 = (x_1 + K_1 \tan 2\theta_x, S_y + K_1, S_z)\f$;
///    \f[ d_2 = d_1 - 2 (d_1 \cdot n_Y)\, n_Y
///            = (\sin 2\theta_x, \cos 2\theta_x \sin 2\theta_y, -\cos 2\theta_x \cos 2\theta_y). \f]
/// 3. Windows: a plate of thickness e crossed with incidence
///    \f$\cos i = \cos 2\theta_x \cos 2\theta_y\f$ changes the horizontal travel over its thickness
///    from \f$e\,d_h / \cos i\f$ to \f$e\,d_h / \sqrt{n_2^2/n_1^2 - 1 + \cos^2 i}\f$ (Snell: the
///    tangential part of \f$n\,d\f$ is kept); hence
///    \f[ K_3 = \sqrt{\cos^2 2\theta_x \cos^2 2\theta_y - 1 + n_2^2 / n_1^2} \f]
///    and the two windows (\f$2 e_v\f$ of glass in total, wherever they are) replace \f$2 e_v\f$ of
///    the descent.
/// 4. Plane: from height \f$H = S_z - z_p\f$, with \f$K_2 = H - 2 e_v\f$ the gas part of the
///    descent,
///    \f[ x = x_1 + K_1 \tan 2\theta_x + \frac{K_2 \tan 2\theta_x}{\cos 2\theta_y}
///            + \frac{2 e_v \sin 2\theta_x}{K_3} - p_x \f]
///    \f[ y = S_y + K_1 + K_2 \tan 2\theta_y + \frac{2 e_v \cos 2\theta_x \sin 2\theta_y}{K_3} - p_y \f]
///    (\f$(p_x, p_y, z_p)\f$ = work-plane origin in the base frame; the nominal plane is
///    horizontal).
///
/// \par OPT's transcribed eqs. 2–6 (SPEC §4) against ours
/// OPT's frames differ from ours (its galvo axes on x, mirror normals on z, per
/// defect_catalog.hpp), but its nominal parameters are positions and angles that can be given
/// values for our head. With
/// - \f$X_p = p_x - S_x,\ Y_p = p_y - S_y,\ Z_p = z_p - S_z = -H\f$ (plane origin in the source
///   frame),
/// - \f$Y_{ay0} = v_y,\ Z_{ay0} = v_z,\ A_{ay0} = 3\pi/4\f$ (axis Y in the source frame),
/// - \f$X_{ax0} = A_{x,x} - S_x,\ Y_{ax0} = S_y - A_{x,y} = -u,\ A_{ax0} = \pi/4,\ B_{ax0} = \pi/2\f$,
///
/// and \f$\theta_x, \theta_y, x, y\f$ with our signs, the transcription reproduces our head
/// exactly (the test OptTranscriptionWithOurParametersMatchesTrace: 9.0e-16 m). Term by term:
/// - eq. 2,
///   \f[ K_1^{OPT} = \frac{e_m + Z_{ay0} \cos(A_{ay0} + \theta_y) - Y_{ay0} \sin(A_{ay0} + \theta_y)}
///                        {\cos(A_{ay0} - B_{ax0} + \theta_y)}
///                 = \frac{e_m - v_z \sin\gamma - v_y \cos\gamma}{\cos\gamma} = -K_1: \f]
///   OPT's \f$K_1\f$ is minus our mirror-to-mirror travel (−20 mm at θ = 0);
///   \f$-K_1^{OPT} \sin B_{ax0}\f$ in eq. 6 is our \f$+K_1\f$, \f$-K_1^{OPT} \tan 2\theta_x\f$ in
///   eq. 5 our \f$+K_1 \tan 2\theta_x\f$, so these signs are consistent.
/// - eq. 3, \f$K_2^{OPT} = Z_p + 2 e_v - K_1^{OPT} \cos B_{ax0} = -(H - 2 e_v) = -K_2\f$
///   (\f$B_{ax0} = \pi/2\f$: our beam between the mirrors is horizontal, so the height of mirror Y
///   does not depend on \f$K_1\f$); \f$-K_2^{OPT} \tan 2\theta_y\f$ (eq. 6) and
///   \f$-K_2^{OPT} \tan 2\theta_x / \cos 2\theta_y\f$ (eq. 5) are our descent terms. "\f$2 e_v\f$"
///   is right: two windows of \f$e_v\f$ each; its sign too (the glass shortens the gas path).
/// - eq. 4, \f$K_3\f$: identical (it needs \f$n_2/n_1\f$, not \f$n_1/n_2\f$, and the product
///   \f$\cos^2 2\theta_x \cos^2 2\theta_y\f$).
/// - eq. 5, \f$2 e_v \sin 2\theta_x / K_3\f$ and eq. 6, \f$2 e_v \cos 2\theta_x \sin 2\theta_y / K_3\f$:
///   identical to ours.
/// - eq. 5, \f$X_{ax0} + (e_m - Y_{ax0} \cos(-A_{ax0} + \theta_x) \sin B_{ax0}) / \sin(-A_{ax0} + \theta_x)\f$:
///   with \f$A_{ax0} = \pi/4\f$, \f$\sin(\theta_x - \pi/4) = -\cos\beta\f$,
///   \f$\cos(\theta_x - \pi/4) = \sin\beta\f$, it is our \f$x_1 - S_x\f$ provided
///   \f$Y_{ax0} = S_y - A_{x,y}\f$, i.e. the offset of the SOURCE from the axis, whereas
///   \f$Y_{ay0}, Z_{ay0}\f$ (eq. 2) are offsets of the axis from the source. Read with the same
///   convention as the other positions (\f$Y_{ax0} = A_{x,y} - S_y\f$), eq. 5 is off by
///   \f$2u \tan\beta = -\sqrt{2}\, e_m \tan(\theta_x + \pi/4)\f$: 3.5 mm at the centre, 4.5 mm at
///   the field's edge, 5.0 mm at the joint limit (test). So either OPT defines the ax0
///   translation the other way round, or the sign before \f$Y_{ax0}\f$ is a transcription error;
///   the \f$\sin B_{ax0}\f$ factor on the \f$Y_{ax0}\f$ term alone (not on \f$e_m\f$) cannot be
///   checked with our head (\f$B_{ax0} = \pi/2\f$, sin = 1).
///
/// Conclusion: eqs. 2–4 and 6 are right as transcribed, eq. 5 holds up to that one sign
/// convention; no factor 2 or index ratio is wrong.
///
/// \par Domain
/// \f$|\theta| < \pi/4\f$ keeps every cosine positive (the joints stop at 0.1745 rad).
///
/// \param[in] nominal the nominal geometry (source, galvo mounts, mirrors, work plane)
/// \param[in] config window thickness \f$e_v\f$ [m] and refractive indices \f$n_1, n_2\f$
/// \param[in] q mechanical angles \f$(\theta_x, \theta_y)\f$ [rad], \f$|\theta| < \pi/4\f$
/// \return the spot in the work-plane frame [m]
/// \pre \p nominal is the nominal geometry (defect frames at identity); the result is
/// meaningless otherwise
Eigen::Vector2d closedFormSpot(const OpticalGeometry& nominal, const OpticsConfig& config, const Eigen::Vector2d& q);
}  // namespace scanhead
