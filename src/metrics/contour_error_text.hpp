/// \file contour_error_text.hpp
/// \brief Private to src/metrics (contour error, path store, grid index): numbers and points in
/// error messages, 17 significant digits.
#pragma once

#include <Eigen/Core>
#include <sstream>
#include <string>

namespace scanhead
{
namespace
{
inline std::string text(double v)
{
  std::ostringstream s;
  s.precision(17);
  s << v;
  return s.str();
}

inline std::string pointText(const Eigen::Vector2d& p)
{
  return "(" + text(p.x()) + ", " + text(p.y()) + ")";
}
}  // namespace
}  // namespace scanhead
