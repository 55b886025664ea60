/// \file nc_config.hpp
/// \brief Parameters of the numerical-control interpolator (SPEC §2): sampling, inverse geometry,
/// filters, delays, skywriting, power modulation, output quantisation.
#pragma once

#include <string>

namespace scanhead
{
/// \brief The inverse geometric transform (SPEC §2.2).
struct IgtConfig
{
  std::string mode = "newton";                   ///< "newton": exact inverse; "table": correction table
  std::string table_file;                        ///< table to load (correction_table.hpp); "": built from the optics
  int table_nodes = 65;                          ///< nodes per axis of a built table (THESIS §2.3.2.2: 65)
  std::string table_interpolation = "bilinear";  ///< "bilinear" (THESIS) | "bicubic" (< 1 µm)

  void validate() const;
};

/// \brief Skywriting: the laser is off through a corner while the mirrors run out along the
/// incoming tangent, turn, and run back in along the outgoing one (also before a mark's first
/// point and after its last). Run length = run_*_m + run_*_s · v (v: the mark's speed).
struct SkywritingConfig
{
  bool enabled = false;
  double run_in_m = 0.0;  ///< run-in before a corner or a mark's start [m]
  double run_in_s =
      300.0e-6;            ///< run-in as a time at the mark speed [s] (> (T1 + T2)/2: full speed at the laser switch)
  double run_out_m = 0.0;  ///< run-out after a corner or a mark's end [m]
  double run_out_s = 300.0e-6;  ///< run-out as a time at the mark speed [s]
  double min_angle_deg = 30.0;  ///< corners turning by more than this are skywritten [deg]

  void validate() const;
};

struct NcConfig
{
  /// Range of the sample period [s]: 1 µs .. 1 ms, i.e. 1 MHz .. 1 kHz, the span of galvo
  /// controllers (the XY2-100 link and the THESIS NC run at 100 kHz, the THESIS bench's servo at
  /// 20 kHz); outside it a setting is a typo (1e-12 s would need 1e12 samples a machine second).
  static constexpr double kMinPeriod_s = 1.0e-6;
  static constexpr double kMaxPeriod_s = 1.0e-3;
  /// Longest box FIR in periods: a filter keeps ceil(T/Ts) + 2 samples a channel and sums them every
  /// period (box_filter.hpp), so T/Ts bounds its memory and work; the industrial NC's are 26 and 12.5.
  static constexpr double kMaxFirPeriods = 10000.0;

  double period_s = 1.0e-5;              ///< Ts, NC sample period [s]
  double fir_t1_s = 260.0e-6;            ///< first box FIR duration [s] (NC §2.2, measured)
  double fir_t2_s = 125.0e-6;            ///< second box FIR duration [s]
  double max_joint_speed_radps = 25.0;   ///< velocity saturation between the FIRs [rad/s]
  double implicit_jump_speed_mps = 4.5;  ///< speed of jumps inserted between non-contiguous polylines [m/s]
  double tail_s = 3.0e-3;                ///< hold time after the path so filters and servos settle [s]
  bool debug = false;                    ///< also produce Q_inter / Q_filt1 (nc/debug)

  IgtConfig igt;

  /// "fixed": box FIRs T1, T2 (the industrial NC); "adaptive": per-speed durations that just meet
  /// the acceleration and jerk limits below (NC §3.5), filtered in the work plane.
  std::string filter_mode = "fixed";
  /// Per-axis limits [rad/s², rad/s³]: the design point of the industrial NC, whose fixed filters
  /// keep any path at the recipe-1 jump speed (6 m/s) within them: |q̈| <= 2·V·g/T1 (a reversal),
  /// |q⃛| <= 4·V·g/(T1·T2) (two reversals within T1), so A = 2·6·g/T1, J = 4·6·g/(T1·T2) with
  /// g = 0.716 rad/m, the largest joint rate per plane speed over the field (Y axis, centre).
  double max_joint_accel_radps2 = 3.3e4;
  double max_joint_jerk_radps3 = 5.29e8;
  bool cap_speeds = false;  ///< fixed filters: slow polylines whose speed would break the limits

  double mark_delay_s = 0.0;                 ///< hold at the end of a MARK polyline before what follows [s]
  double jump_delay_s = 0.0;                 ///< hold at the end of a jump before what follows [s]
  double polygon_delay_s = 0.0;              ///< hold at each corner inside a MARK polyline, laser on [s]
  std::string polygon_delay_mode = "fixed";  ///< "fixed" | "angle" (scaled by turn angle / 180°)
  SkywritingConfig skywriting;

  /// "constant" | "speed": P·clamp(v / v_prog, floor, 1) with v the filtered path's speed |Ẋ_filt2|
  /// (NC §5) | "predicted": v the actual path's, predicted by the servo model run on the setpoint
  std::string power_mode = "constant";
  double power_floor = 0.2;  ///< lowest power fraction in "speed" mode, in [0, 1]

  int quantisation_bits = 0;  ///< XY2-100 setpoint word: 0 (off), 16, 18 or 20 bits over the joint range

  /// \brief Delay of the filtered setpoint behind the sampled path with fixed filters: (T1 + T2) / 2 [s].
  double filterDelay() const { return 0.5 * (fir_t1_s + fir_t2_s); }
  /// \brief The speed the NC caps every polyline at [m/s], for the largest joint rate per plane
  /// speed \p joint_gain_rad_per_m (infinity: no cap). Adaptive filters: the joint speed limit (that
  /// path has no rate limiter). Fixed filters with cap_speeds: any path at V through box T1 then box
  /// T2 has |q̈| <= 2gV/T1 (a reversal) and |q⃛| <= 4gV/(T1·T2) (two reversals within T1): bounds,
  /// not estimates, so V <= min(A·T1/2, J·T1·T2/4)/g keeps both limits.
  double speedCap(double joint_gain_rad_per_m) const;

  /// \throws ConfigError naming the field and value
  void validate() const;
};
}  // namespace scanhead
