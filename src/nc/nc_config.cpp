/// \file nc_config.cpp
/// \brief Validation of the NC parameters (SPEC §2).
#include "scanhead/nc/nc_config.hpp"

#include <algorithm>
#include <limits>

#include "scanhead/common/config_check.hpp"

namespace scanhead
{
void IgtConfig::validate() const
{
  requireChoice(mode, "nc.igt.mode", {"newton", "table"});
  // A built table costs nodes² Newton solves before the run (1025²: ~2 s, 60 MB; 4097²: ~1 min,
  // 1.2 GB, measured); the THESIS's is 65 and bicubic is within 1 µm from 65 on.
  if (table_nodes < 2 || table_nodes > 1025)
    failSetting("nc.igt.table_nodes", "in 2...1025 (a built table costs nodes² Newton solves; THESIS: 65)",
                table_nodes);
  requireChoice(table_interpolation, "nc.igt.table_interpolation", {"bilinear", "bicubic"});
}

void SkywritingConfig::validate() const
{
  requireSetting(run_in_m >= 0.0, "nc.skywriting.run_in_m", ">= 0", run_in_m);
  requireSetting(run_in_s >= 0.0, "nc.skywriting.run_in_s", ">= 0", run_in_s);
  requireSetting(run_out_m >= 0.0, "nc.skywriting.run_out_m", ">= 0", run_out_m);
  requireSetting(run_out_s >= 0.0, "nc.skywriting.run_out_s", ">= 0", run_out_s);
  requireSetting(min_angle_deg >= 0.0 && min_angle_deg < 180.0, "nc.skywriting.min_angle_deg", "in [0, 180)",
                 min_angle_deg);
}

double NcConfig::speedCap(double joint_gain_rad_per_m) const
{
  if (filter_mode == "adaptive")
    return max_joint_speed_radps / joint_gain_rad_per_m;
  if (cap_speeds)
    return std::min(max_joint_accel_radps2 * fir_t1_s / 2.0, max_joint_jerk_radps3 * fir_t1_s * fir_t2_s / 4.0) /
           joint_gain_rad_per_m;
  return std::numeric_limits<double>::infinity();
}

void NcConfig::validate() const
{
  requireSetting(period_s > 0.0, "nc.period_s", "> 0", period_s);
  requireSetting(fir_t1_s >= 0.0, "nc.fir_t1_s", ">= 0", fir_t1_s);
  requireSetting(fir_t2_s >= 0.0, "nc.fir_t2_s", ">= 0", fir_t2_s);
  requireSetting(max_joint_speed_radps > 0.0, "nc.max_joint_speed_radps", "> 0", max_joint_speed_radps);
  requireSetting(implicit_jump_speed_mps > 0.0, "nc.implicit_jump_speed_mps", "> 0", implicit_jump_speed_mps);
  requireSetting(tail_s >= 0.0, "nc.tail_s", ">= 0", tail_s);
  // The controller's range (nc_config.hpp): every stage's work per machine second grows as 1/Ts.
  requireSetting(period_s >= kMinPeriod_s && period_s <= kMaxPeriod_s, "nc.period_s",
                 "in [1e-06, 0.001] s (1 MHz .. 1 kHz, the range of galvo controllers; XY2-100 runs at 100 kHz)",
                 period_s);
  // A box FIR holds and sums T/Ts samples a channel every period.
  requireSetting(
      fir_t1_s <= kMaxFirPeriods * period_s, "nc.fir_t1_s",
      "<= 10000·nc.period_s (its memory and work per sample grow with T/Ts; industrial NCs: tens of periods)",
      fir_t1_s);
  requireSetting(
      fir_t2_s <= kMaxFirPeriods * period_s, "nc.fir_t2_s",
      "<= 10000·nc.period_s (its memory and work per sample grow with T/Ts; industrial NCs: tens of periods)",
      fir_t2_s);
  igt.validate();
  requireChoice(filter_mode, "nc.filter_mode", {"fixed", "adaptive"});
  requireSetting(max_joint_accel_radps2 > 0.0, "nc.max_joint_accel_radps2", "> 0", max_joint_accel_radps2);
  requireSetting(max_joint_jerk_radps3 > 0.0, "nc.max_joint_jerk_radps3", "> 0", max_joint_jerk_radps3);
  requireSetting(mark_delay_s >= 0.0, "nc.mark_delay_s", ">= 0", mark_delay_s);
  requireSetting(jump_delay_s >= 0.0, "nc.jump_delay_s", ">= 0", jump_delay_s);
  requireSetting(polygon_delay_s >= 0.0, "nc.polygon_delay_s", ">= 0", polygon_delay_s);
  requireChoice(polygon_delay_mode, "nc.polygon_delay_mode", {"fixed", "angle"});
  skywriting.validate();
  requireChoice(power_mode, "nc.power_mode", {"constant", "speed", "predicted"});
  requireSetting(power_floor >= 0.0 && power_floor <= 1.0, "nc.power_floor", "in [0, 1]", power_floor);
  if (quantisation_bits != 0 && quantisation_bits != 16 && quantisation_bits != 18 && quantisation_bits != 20)
    failSetting("nc.quantisation_bits", "0 (off), 16, 18 or 20", quantisation_bits);
}
}  // namespace scanhead
