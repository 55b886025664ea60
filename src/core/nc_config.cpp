/// \file nc_config.cpp
/// \brief Validation of the NC parameters (SPEC §2).
#include "scanhead/core/nc_config.hpp"

#include <cmath>
#include <sstream>
#include <string>

#include "scanhead/core/errors.hpp"

namespace scanhead
{
namespace
{
void require(bool ok, const char* field, const char* condition, double value)
{
  if (!ok)
  {
    std::ostringstream msg;
    const bool infinite = std::isinf(value);
    msg << "nc." << field << " must be " << (infinite ? "finite" : condition) << " (got " << value << ")";
    throw ConfigError(msg.str());
  }
}
}  // namespace

void NcConfig::validate() const
{
  // Written as !(x > 0) etc. so NaN fails every check; infinities are rejected explicitly.
  require(std::isfinite(period_s) && period_s > 0.0, "period_s", "> 0", period_s);
  require(std::isfinite(fir_t1_s) && fir_t1_s >= 0.0, "fir_t1_s", ">= 0", fir_t1_s);
  require(std::isfinite(fir_t2_s) && fir_t2_s >= 0.0, "fir_t2_s", ">= 0", fir_t2_s);
  require(std::isfinite(max_joint_speed_radps) && max_joint_speed_radps > 0.0, "max_joint_speed_radps", "> 0",
          max_joint_speed_radps);
  require(std::isfinite(implicit_jump_speed_mps) && implicit_jump_speed_mps > 0.0, "implicit_jump_speed_mps", "> 0",
          implicit_jump_speed_mps);
  require(std::isfinite(tail_s) && tail_s >= 0.0, "tail_s", ">= 0", tail_s);
}
}  // namespace scanhead
