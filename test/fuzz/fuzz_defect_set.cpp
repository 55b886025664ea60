/// \file fuzz_defect_set.cpp
/// \brief libFuzzer target over the defect set reader (parseDefectSet): any input must either give
/// a set of 30 finite values or throw InputError; a set that reads must write (defectSetToYaml)
/// and read back bit-exactly. Build: see fuzz_smoke.sh.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>

#include "scanhead/common/errors.hpp"
#include "scanhead/optics/defect_set_io.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
  const std::string text(reinterpret_cast<const char*>(data), size);
  scanhead::DefectSet set;
  try
  {
    set = scanhead::parseDefectSet(text, "fuzz.yaml");
  }
  catch (const scanhead::InputError&)
  {
    return 0;
  }
  for (const double v : set.values)
    if (!std::isfinite(v))
      __builtin_trap();
  const scanhead::DefectSet back = scanhead::parseDefectSet(scanhead::defectSetToYaml(set), "fuzz.yaml");
  if (back.name != set.name || back.values != set.values)
    __builtin_trap();
  return 0;
}
