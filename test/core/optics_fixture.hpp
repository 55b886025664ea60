/// \file optics_fixture.hpp
/// \brief The nominal head the optics tests share.
#pragma once

#include <string>

#include "scanhead/core/optical_model.hpp"

namespace scanhead::test_support
{
inline const std::string kNominalUrdfPath = std::string(SCANHEAD_SOURCE_DIR) + "/urdf/scanhead.urdf";

/// \brief urdf/scanhead.urdf, read once.
inline const OpticalGeometry& nominalGeometry()
{
  static const OpticalGeometry geometry = geometryFromUrdfFile(kNominalUrdfPath);
  return geometry;
}
}  // namespace scanhead::test_support
