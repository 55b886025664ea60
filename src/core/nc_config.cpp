/// \file nc_config.cpp
/// \brief Validation of the NC parameters (SPEC §2).
#include "scanhead/core/nc_config.hpp"


#include "scanhead/core/config_check.hpp"

namespace scanhead
{
void NcConfig::validate() const
{
  requireSetting(period_s > 0.0, "nc.period_s", "> 0", period_s);
  requireSetting(fir_t1_s >= 0.0, "nc.fir_t1_s", ">= 0", fir_t1_s);
  requireSetting(fir_t2_s >= 0.0, "nc.fir_t2_s", ">= 0", fir_t2_s);
  requireSetting(max_joint_speed_radps > 0.0, "nc.max_joint_speed_radps", "> 0",
          max_joint_speed_radps);
  requireSetting(implicit_jump_speed_mps > 0.0, "nc.implicit_jump_speed_mps", "> 0",
          implicit_jump_speed_mps);
  requireSetting(tail_s >= 0.0, "nc.tail_s", ">= 0", tail_s);
}
}  // namespace scanhead
