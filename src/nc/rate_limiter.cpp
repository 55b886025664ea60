/// \file rate_limiter.cpp
/// \brief Velocity saturation (SPEC §2.4).
#include "scanhead/nc/rate_limiter.hpp"

#include <cmath>
#include <sstream>

#include "scanhead/common/errors.hpp"

namespace scanhead
{
RateLimiter::RateLimiter(double max_rate, double period_s)
  : max_rate_(max_rate)
  , max_step_(max_rate * period_s)
{
  if (!(std::isfinite(max_rate) && max_rate > 0.0) || !(std::isfinite(period_s) && period_s > 0.0))
  {
    std::ostringstream msg;
    msg << "RateLimiter: max rate and period must be > 0 (got rate " << max_rate << ", period " << period_s << " s)";
    throw ConfigError(msg.str());
  }
}
}  // namespace scanhead
