/// \file contour_error_text.hpp
/// \brief Private to src/metrics (contour error, path store, grid index, fill rate): points in
/// error messages, 17 significant digits (fullPrecisionText, "%.17g").
#pragma once

#include <Eigen/Core>
#include <string>

#include "scanhead/common/number_text.hpp"

namespace scanhead
{
namespace
{
/// "(x, y)" with each coordinate as fullPrecisionText.
inline std::string pointText(const Eigen::Vector2d& p)
{
  return "(" + fullPrecisionText(p.x()) + ", " + fullPrecisionText(p.y()) + ")";
}
}  // namespace
}  // namespace scanhead
