/// \file optical_defects.hpp
/// \brief The assembly defects in one include: the 30 defects and defect sets
/// (defect_catalog.hpp), defect set files (defect_set_io.hpp), the set specs of the settings and
/// tools (defect_set_spec.hpp) and the URDF of a defective machine (urdf_defects.hpp).
#pragma once

#include "scanhead/optics/defect_catalog.hpp"
#include "scanhead/optics/defect_set_io.hpp"
#include "scanhead/optics/defect_set_spec.hpp"
#include "scanhead/optics/urdf_defects.hpp"
