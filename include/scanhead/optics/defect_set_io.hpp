/// \file defect_set_io.hpp
/// \brief Defect set files (docs/defects.md): YAML maps element → {component: value} in mm and
/// mrad, read with their file, line and key in every error, and written at full precision.
#pragma once

#include <string>

#include "scanhead/optics/defect_catalog.hpp"

namespace scanhead
{
/// \brief Reads a defect set file: a YAML map element → {component: value}, mm and mrad, e.g.
/// \code
/// name: opt_table2
/// source:     {y: -0.063, z: -0.085, b: -0.069, c: -0.065}
/// mirror_x:   {z: -0.025, a: -0.062, b: 0.029}
/// \endcode
/// Missing entries are zero, an optional top-level `name:` (default: the file name without its
/// extension), an empty file is the nominal set; any other key (an unknown element, or a
/// component that is not one of the 30 defects, e.g. mirror_x.x) is an error.
/// \throws InputError naming the file, line and key, and listing the allowed ones
DefectSet loadDefectSet(const std::string& path);

/// \brief The defect set file format of loadDefectSet from text; \p path names it in errors and
/// gives the default name (the fuzz target).
DefectSet parseDefectSet(const std::string& text, const std::string& path);

/// \brief The set as a defect set file: a comment line, `name:`, then one line per element with
/// all its components, each the shortest text that reads back bit-exactly (loadDefectSet
/// round-trips it).
std::string defectSetToYaml(const DefectSet& set);
}  // namespace scanhead
