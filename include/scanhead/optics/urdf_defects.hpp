/// \file urdf_defects.hpp
/// \brief The URDF of a defective machine: the nominal URDF text with the origins of its 8
/// defect joints (defectJointElements()) written from a defect set. The batch runner and the ROS
/// graph both build the machine from this text, so it is produced by editing the given text in
/// place (everything else byte for byte), with TinyXML locating the joints and origins.
#pragma once

#include <string>

#include "scanhead/optics/defect_catalog.hpp"

namespace scanhead
{
/// \brief \p nominal_urdf with the origins of the 8 `<element>_defect_joint` joints (the
/// `<joint>` children of `<robot>`) replaced by elementDefects(set), written as
/// `<origin xyz="x y z" rpy="r p y"/>` with 17 significant digits. A joint without `<origin>`
/// (identity) gets one before `</joint>`, on its own line indented two spaces more than
/// `</joint>` when that stands on its own line. Everything else (comments, spacing, line ends)
/// is unchanged. A nominal set returns the text as it is, unparsed (a URDF that already carries
/// defects in its joints keeps them).
/// \throws InputError naming \p source_name if the text is not well-formed XML (with TinyXML's
/// message, line and column), has no `<robot>` root, or a defect joint is missing, appears twice,
/// is empty (`<joint .../>`) or already carries a non-zero origin
std::string urdfWithDefects(const std::string& nominal_urdf, const DefectSet& set, const std::string& source_name);
}  // namespace scanhead
