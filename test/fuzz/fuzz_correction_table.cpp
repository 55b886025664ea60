/// \file fuzz_correction_table.cpp
/// \brief libFuzzer target over the correction table reader (CorrectionTable::parse): any input
/// must either give a table of n >= 2 nodes per axis over a finite (0, 1] m half field, or throw
/// InputError (the node count is checked against the text's size before n² nodes are allocated).
/// A table that reads must save and read back with the same nodes. Build: see fuzz_smoke.sh.
#include <unistd.h>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>

#include "scanhead/common/errors.hpp"
#include "scanhead/optics/correction_table.hpp"

// The reader never evaluates the optics (only CorrectionTable::build and measureTableError do), and
// the optical model's AVX clones do not build with clang's libFuzzer flags: the three members the
// rest of correction_table.cpp refers to trap if they are ever reached.
namespace scanhead
{
OpticalModel::Ray OpticalModel::trace(const Eigen::Vector2d&) const
{
  __builtin_trap();
}
Eigen::Matrix2d OpticalModel::jacobian(const Eigen::Vector2d&) const
{
  __builtin_trap();
}
Eigen::Vector2d OpticalModel::inverse(const Eigen::Vector2d&, const Eigen::Vector2d&) const
{
  __builtin_trap();
}
}  // namespace scanhead

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
  const std::string text(reinterpret_cast<const char*>(data), size);
  scanhead::CorrectionTable table;
  try
  {
    table = scanhead::CorrectionTable::parse(text, "fuzz.table");
  }
  catch (const scanhead::InputError&)
  {
    return 0;
  }
  if (table.nodes() < 2 || !(table.halfWidth() > 0.0) || !(table.halfWidth() <= 1.0))
    __builtin_trap();
  // Round trip through the writer: the saved text must read back to the same interpolation.
  static const std::string path = "/tmp/fuzz_correction_table." + std::to_string(::getpid()) + ".txt";
  table.save(path);
  const scanhead::CorrectionTable back = scanhead::CorrectionTable::load(path);
  std::remove(path.c_str());
  if (back.nodes() != table.nodes() || back.halfWidth() != table.halfWidth())
    __builtin_trap();
  const double h = table.halfWidth();
  for (const double fx : {-1.0, -0.3, 0.0, 0.7, 1.0})
    for (const double fy : {-1.0, 0.2, 1.0})
    {
      const Eigen::Vector2d x(fx * h, fy * h);
      const Eigen::Vector2d a = table.joints(x, scanhead::TableInterpolation::Bicubic);
      const Eigen::Vector2d b = back.joints(x, scanhead::TableInterpolation::Bicubic);
      if (!(a == b) && (a.allFinite() || b.allFinite()))
        __builtin_trap();
    }
  return 0;
}
