/// \file nominal_closed_form.hpp
/// \brief The direct model of the nominal head in closed form (SPEC §4, OPT eqs. 2–6), an
/// independent cross-check of the ray trace (OpticalModel::trace).
#pragma once

#include <Eigen/Core>

#include "scanhead/optics/optical_model.hpp"

namespace scanhead
{
/// \brief Spot (x, y) on the work plane [m] of the nominal machine \p nominal at mechanical
/// angles \p q [rad], from closed-form expressions (no ray marching: the derivation and how it
/// relates to OPT's transcribed eqs. 2–6 are in nominal_closed_form.cpp).
/// \pre \p nominal is the nominal geometry (defect frames at identity); the result is
/// meaningless otherwise
Eigen::Vector2d closedFormSpot(const OpticalGeometry& nominal, const OpticsConfig& config, const Eigen::Vector2d& q);
}  // namespace scanhead
