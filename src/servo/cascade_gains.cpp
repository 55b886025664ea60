/// \file cascade_gains.cpp
#include "scanhead/servo/cascade_gains.hpp"

#include "scanhead/common/config_check.hpp"

namespace scanhead
{
void CascadeGains::validate(const std::string& prefix) const
{
  const std::string p = prefix + ".";
  requireSetting(kii > 0.0, p + "kii", "> 0", kii);
  requireSetting(tii_s > 0.0, p + "tii_s", "> 0", tii_s);
  requireSetting(kiw > 0.0, p + "kiw", "> 0", kiw);
  requireSetting(tiw_s > 0.0, p + "tiw_s", "> 0", tiw_s);
  requireSetting(ktheta > 0.0, p + "ktheta", "> 0", ktheta);
  requireSetting(tdtheta_s >= 0.0, p + "tdtheta_s", ">= 0", tdtheta_s);
  requireSetting(tauf_s >= 0.0, p + "tauf_s", ">= 0", tauf_s);
  requireSetting(k1 >= 0.0 && k1 <= 1.0, p + "k1", "in [0, 1]", k1);
  requireSetting(k2 >= 0.0 && k2 <= 1.0, p + "k2", "in [0, 1]", k2);
}
}  // namespace scanhead
