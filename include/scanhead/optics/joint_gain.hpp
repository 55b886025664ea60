/// \file joint_gain.hpp
/// \brief How fast the joints turn per unit of spot speed, over the field: the factor between the
/// NC's per-axis joint limits [rad/s², rad/s³] and the work-plane motion it plans.
#pragma once

#include <Eigen/Core>

#include "scanhead/optics/optical_model.hpp"

namespace scanhead
{
/// \brief g_i = max over the field of |row_i(J⁻¹)| [rad/m], J = d(spot)/dq, so that
/// \f[ |\dot q_i| \le g_i\,|\dot x|,\qquad |\ddot q_i| \lesssim g_i\,|\ddot x| \f]
/// (the second up to the curvature term J̇ q̇: 0.05 % of the NC's acceleration limit at 6 m/s,
/// 0.22 % at 12 m/s, 1.8 % at 35 m/s; the planner's limits keep that margin in mind).
/// Sampled on a probes × probes grid over [−h, h]², corners and centre included (the gain is
/// largest at the centre and falls towards the edges for this head).
/// \throws NumericalError if a probe is unreachable
Eigen::Vector2d jointRateGains(const OpticalModel& optics, double half_width_m, int probes = 21);
}  // namespace scanhead
