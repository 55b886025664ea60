/// \file cascade_gains.hpp
/// \brief Gains of the cascaded current / speed / position loops with feedforward (SPEC §3,
/// THESIS Fig. 2.26–2.29), SI units with angles in radians.
#pragma once

#include <string>

namespace scanhead
{
/// \brief Controller of one galvo axis:
/// \f[ REG_i = K_{ii}\Big(1 + \frac{1}{T_{ii}s}\Big),\quad REG_\omega = K_{i\omega}\Big(1 +
/// \frac{1}{T_{i\omega}s}\Big),\quad
///     REG_\theta = K_\theta\Big(1 + \frac{T_{d\theta}s}{1 + T_{d\theta}s/100}\Big), \f]
/// \f[ FF_\omega = K_1\frac{s}{1 + \tau_f s},\qquad FF_i = K_2\frac{J_{eq}}{K_c}\frac{s^2}{(1 + \tau_f s)^2}. \f]
/// Defaults are the Y galvo's (see galvo_params.hpp for both axes and their synthesis).
struct CascadeGains
{
  double kii = 1.76159;          ///< Kii, current PI gain [V/A]
  double tii_s = 7.05149e-5;     ///< Tii, current PI integral time [s]
  double kiw = 0.0418529;        ///< Kiω, speed PI gain [A/(rad/s)]
  double tiw_s = 5.0e-3;         ///< Tiω, speed PI integral time [s]
  double ktheta = 33.4352;       ///< Kθ, position PD gain [(rad/s)/rad]
  double tdtheta_s = 0.0857140;  ///< Tdθ, position PD derivative time [s] (filter Tdθ/100)
  double tauf_s = 1.0e-5;        ///< τf, feedforward derivative filter [s]
  double k1 = 1.0;               ///< K1, speed feedforward weight (THESIS: 1)
  double k2 = 1.0;               ///< K2, current feedforward weight (THESIS: 1)

  /// \throws ConfigError "<prefix>.<field> must be ... (got ...)" (gains and times > 0, τf >= 0,
  /// K1, K2 in [0, 1])
  void validate(const std::string& prefix) const;
};
}  // namespace scanhead
