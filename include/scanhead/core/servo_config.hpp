/// \file servo_config.hpp
/// \brief Parameters of the per-axis galvo servo models.
#pragma once

#include <string>

namespace scanhead
{
/// \brief Closed-loop third-order model θ/θref = ωn²·p / ((s² + 2ζωn s + ωn²)(s + p)).
///
/// Defaults (design choice of this project, SPEC §3 gives targets, not this model): ζ = 0.7 and
/// p = 1.5 ωn give a step overshoot of a few % and a monotone-ish gain (no resonance peak), in line
/// with the 75° phase margin of the bench's position loop (THESIS §2.2.2.2); the real pole stands
/// for the lag of the inner speed/current loops.
struct AxisLoopConfig
{
  double bandwidth_hz = 1000.0;  ///< -3 dB frequency of θ/θref [Hz]; ωn is solved from it
  double damping = 0.7;          ///< ζ of the complex pole pair
  double pole_ratio = 1.5;       ///< p / ωn, the real pole

  /// \throws ConfigError "servo.<axis>.<field> must be > 0 (got <value>)" (bandwidth_hz, damping,
  /// pole_ratio; NaN rejected). The bound against the sample rate is checked by GalvoServo.
  void validate(const std::string& axis) const;
};

struct ServoConfig
{
  std::string model = "closed_loop_3rd_order";  ///< the only model of this issue
  AxisLoopConfig x{1300.0, 0.7, 1.5};             ///< X: lighter mirror, faster (NC Fig. 4)
  AxisLoopConfig y{1000.0, 0.7, 1.5};             ///< Y: THESIS bench, ≈ 1 kHz
  double kc_over_jeq = 1.2e5;                     ///< Kc/Jeq [rad/s²/A] to report current (SPEC §3)

  /// \throws ConfigError naming the field and value (unknown model, axis fields, kc_over_jeq)
  void validate() const;
};
}  // namespace scanhead
