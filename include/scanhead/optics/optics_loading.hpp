/// \file optics_loading.hpp
/// \brief The optical model and defect set a configuration names, read from the package's files.
#pragma once

#include "scanhead/optics/defect_catalog.hpp"
#include "scanhead/optics/optical_model.hpp"
#include "scanhead/optics/optics_config.hpp"

namespace scanhead
{
/// \brief The optical model the config names: the nominal URDF (resolved with resolvePackagePath)
/// with the defect set optics.defects applied.
OpticalModel loadOpticalModel(const OpticsConfig& config);

/// \brief The defect set optics.defects names (a .yaml file resolved with resolvePackagePath).
DefectSet loadDefects(const OpticsConfig& config);
}  // namespace scanhead
