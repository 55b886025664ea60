/// \file defect_set_spec.cpp
/// \brief defectSetByName: nominal, opt_table2, random:seed=N[,mm=B][,mrad=B] or a file.
#include "scanhead/optics/defect_set_spec.hpp"

#include <cerrno>
#include <cstdint>
#include <cstdlib>

#include "scanhead/common/errors.hpp"
#include "scanhead/common/number_text.hpp"
#include "scanhead/optics/defect_set_io.hpp"

namespace scanhead
{
DefectSet defectSetByName(const std::string& spec)
{
  const std::string forms =
      "nominal, opt_table2, random:seed=N[,mm=B][,mrad=B] (uniform in ±B mm / ±B mrad, default 0.1) or a defect set "
      "file (.yaml)";
  if (spec == "nominal")
    return DefectSet();
  if (spec == "opt_table2")
    return optTable2DefectSet();
  auto endsWith = [&spec](const char* suffix) {
    const std::string s(suffix);
    return spec.size() > s.size() && spec.compare(spec.size() - s.size(), s.size(), s) == 0;
  };
  if (endsWith(".yaml") || endsWith(".yml"))
    return loadDefectSet(spec);
  if (spec == "random" || spec.rfind("random:", 0) == 0)
  {
    auto fail = [&](const std::string& what) {
      throw InputError("defect set '" + spec + "': " + what + " (forms: " + forms + ")");
    };
    bool has_seed = false;
    std::uint64_t seed = 0;
    double bounds[2] = {0.1, 0.1};
    bool has_bound[2] = {false, false};
    const std::string rest = spec.size() > 7 ? spec.substr(7) : std::string();
    std::size_t start = 0;
    while (start <= rest.size() && !rest.empty())
    {
      const std::size_t comma = rest.find(',', start);
      const std::string item = rest.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
      const std::size_t eq = item.find('=');
      const std::string key = item.substr(0, eq);
      const std::string value = eq == std::string::npos ? std::string() : item.substr(eq + 1);
      if (eq == std::string::npos)
        fail("'" + item + "' is not key=value");
      if (key == "seed")
      {
        if (has_seed)
          fail("seed given twice");
        errno = 0;
        char* end = nullptr;
        const unsigned long long parsed = std::strtoull(value.c_str(), &end, 10);
        if (value.empty() || value.find_first_not_of("0123456789") != std::string::npos || *end != '\0' ||
            errno == ERANGE)
          fail("seed must be an integer in [0, 2^64) (got '" + value + "')");
        seed = static_cast<std::uint64_t>(parsed);
        has_seed = true;
      }
      else if (key == "mm" || key == "mrad")
      {
        const int which = key == "mm" ? 0 : 1;
        if (has_bound[which])
          fail(key + " given twice");
        double bound = 0.0;
        if (parseNumber(value, bound) != NumberText::Ok || bound < 0.0)
          fail(key + " must be a number >= 0 (got '" + value + "')");
        bounds[which] = bound;
        has_bound[which] = true;
      }
      else
      {
        fail("unknown key '" + key + "' (keys: seed, mm, mrad)");
      }
      if (comma == std::string::npos)
        break;
      start = comma + 1;
    }
    if (!has_seed)
      fail("needs seed=N");
    return randomDefectSet(seed, bounds[0], bounds[1]);
  }
  throw InputError("unknown defect set '" + spec + "' (forms: " + forms + ")");
}
}  // namespace scanhead
