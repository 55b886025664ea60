/// \file defect_set_spec.hpp
/// \brief Choosing a defect set by a one-word spec (the `defects` setting, the tools'
/// `--defects`): a built-in set, a seeded random set or a defect set file.
#pragma once

#include <string>

#include "scanhead/optics/defect_catalog.hpp"

namespace scanhead
{
/// \brief The set named by \p spec, one of
/// \code
/// nominal                            all zero
/// opt_table2                         optTable2DefectSet()
/// random:seed=N[,mm=B][,mrad=B]      randomDefectSet(N, B_mm = 0.1, B_mrad = 0.1), keys in any order
/// path/to/set.yaml (or .yml)         loadDefectSet(path)
/// \endcode
/// N is a decimal integer in [0, 2^64), B a number >= 0; each key at most once.
/// \throws InputError (bad file or spec: names it and lists the forms)
DefectSet defectSetByName(const std::string& spec);
}  // namespace scanhead
