/// \file nc_config.hpp
/// \brief Parameters of the numerical-control interpolator (SPEC §2).
#pragma once

namespace scanhead
{
struct NcConfig
{
  double period_s = 1.0e-5;               ///< Ts, NC sample period [s]
  double fir_t1_s = 260.0e-6;             ///< first box FIR duration [s] (NC §2.2, measured)
  double fir_t2_s = 125.0e-6;             ///< second box FIR duration [s]
  double max_joint_speed_radps = 25.0;    ///< velocity saturation between the FIRs [rad/s]
  double implicit_jump_speed_mps = 4.5;   ///< speed of jumps inserted between non-contiguous polylines [m/s]
  double tail_s = 3.0e-3;                 ///< hold time after the path so filters and servos settle [s]
  bool debug = false;                     ///< also produce Q_inter / Q_filt1 (nc/debug)

  /// \brief Delay of the filtered setpoint behind the sampled path: (T1 + T2) / 2 [s].
  double filterDelay() const { return 0.5 * (fir_t1_s + fir_t2_s); }

  /// \throws ConfigError naming the field and value
  void validate() const;
};
}  // namespace scanhead
