/// \file optical_geometry_urdf.cpp
/// \brief geometryFromUrdf: composes the frames of the optical chain from the URDF (urdfdom).
#include <urdf_parser/urdf_parser.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

#include "scanhead/common/errors.hpp"
#include "scanhead/optics/optical_model.hpp"

namespace scanhead
{
namespace
{
const char* const kBaseLink = "scanhead_base";

Eigen::Isometry3d toIsometry(const urdf::Pose& pose)
{
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.translation() = Eigen::Vector3d(pose.position.x, pose.position.y, pose.position.z);
  t.linear() = Eigen::Quaterniond(pose.rotation.w, pose.rotation.x, pose.rotation.y, pose.rotation.z)
                   .normalized()
                   .toRotationMatrix();
  return t;
}

class UrdfReader
{
public:
  UrdfReader(const urdf::ModelInterfaceSharedPtr& model, const std::string& source_name)
    : model_(model)
    , source_name_(source_name)
  {
  }

  [[noreturn]] void fail(const std::string& what) const { throw InputError(source_name_ + ": " + what); }

  urdf::LinkConstSharedPtr link(const std::string& name) const
  {
    urdf::LinkConstSharedPtr l = model_->getLink(name);
    if (!l)
    {
      fail("missing link '" + name + "'");
    }
    return l;
  }

  urdf::JointConstSharedPtr joint(const std::string& name) const
  {
    urdf::JointConstSharedPtr j = model_->getJoint(name);
    if (!j)
    {
      fail("missing joint '" + name + "'");
    }
    return j;
  }

  /// Pose of link \p name in link \p ancestor, through fixed joints only.
  Eigen::Isometry3d rigidPose(const std::string& name, const std::string& ancestor) const
  {
    Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
    urdf::LinkConstSharedPtr l = link(name);
    while (l->name != ancestor)
    {
      const urdf::JointSharedPtr& j = l->parent_joint;
      if (!j)
      {
        fail("link '" + name + "' is not below link '" + ancestor + "'");
      }
      if (j->type != urdf::Joint::FIXED)
      {
        fail("joint '" + j->name + "' between '" + ancestor + "' and '" + name + "' must be fixed");
      }
      t = toIsometry(j->parent_to_joint_origin_transform) * t;
      l = link(j->parent_link_name);
    }
    return t;
  }

  /// Galvo joint \p name: checks type and axis, returns the mount (parent pose in the base times
  /// the joint origin), sets \p rotor to the child link, intersects [lower, upper] with its limits.
  Eigen::Isometry3d galvo(const std::string& name, std::string& rotor, double& lower, double& upper) const
  {
    urdf::JointConstSharedPtr j = joint(name);
    if (j->type != urdf::Joint::REVOLUTE)
    {
      fail("joint '" + name + "' must be revolute");
    }
    const double tol = 1e-12;
    if (std::abs(j->axis.x) > tol || std::abs(j->axis.y) > tol || std::abs(j->axis.z - 1.0) > tol)
    {
      std::ostringstream msg;
      msg << "joint '" << name << "' axis must be (0, 0, 1) (got (" << j->axis.x << ", " << j->axis.y << ", "
          << j->axis.z << "))";
      fail(msg.str());
    }
    if (!j->limits || !(j->limits->lower < j->limits->upper))
    {
      fail("joint '" + name + "' needs <limit> with lower < upper");
    }
    lower = std::max(lower, j->limits->lower);
    upper = std::min(upper, j->limits->upper);
    rotor = j->child_link_name;
    return rigidPose(j->parent_link_name, kBaseLink) * toIsometry(j->parent_to_joint_origin_transform);
  }

private:
  urdf::ModelInterfaceSharedPtr model_;
  std::string source_name_;
};
}  // namespace

OpticalGeometry geometryFromUrdf(const std::string& urdf_xml, const std::string& source_name)
{
  const urdf::ModelInterfaceSharedPtr model = urdf::parseURDF(urdf_xml);
  if (!model)
  {
    throw InputError(source_name + ": URDF parse failure (urdfdom rejected the XML)");
  }
  const UrdfReader reader(model, source_name);
  reader.link(kBaseLink);

  OpticalGeometry g;
  g.source = reader.rigidPose("laser_source_defect", kBaseLink);
  double lower = -HUGE_VAL;
  double upper = HUGE_VAL;
  std::string rotor;
  g.mount_x = reader.galvo("galvo_x", rotor, lower, upper);
  g.mirror_x = reader.rigidPose("mirror_x_defect", rotor);
  g.mount_y = reader.galvo("galvo_y", rotor, lower, upper);
  g.mirror_y = reader.rigidPose("mirror_y_defect", rotor);
  g.window_1 = reader.rigidPose("window_1_defect", kBaseLink);
  g.window_2 = reader.rigidPose("window_2_defect", kBaseLink);
  g.work_plane = reader.rigidPose("work_plane_defect", kBaseLink);
  if (!(lower < upper))
  {
    reader.fail("galvo_x and galvo_y joint limits do not overlap");
  }
  g.joint_lower_rad = lower;
  g.joint_upper_rad = upper;
  return g;
}

std::string readUrdfFile(const std::string& path)
{
  std::ifstream in(path);
  if (!in)
  {
    throw InputError(path + ": cannot open URDF file");
  }
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

OpticalGeometry geometryFromUrdfFile(const std::string& path)
{
  return geometryFromUrdf(readUrdfFile(path), path);
}
}  // namespace scanhead
