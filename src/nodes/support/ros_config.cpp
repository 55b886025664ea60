#include "ros_config.hpp"

#include <xmlrpcpp/XmlRpcValue.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "scanhead/chain/config_io.hpp"
#include "scanhead/common/errors.hpp"
#include "scanhead/common/number_text.hpp"
#include "scanhead/optics/optics_loading.hpp"

namespace scanhead
{
namespace
{
std::string scalarText(XmlRpc::XmlRpcValue& value)
{
  switch (value.getType())
  {
    case XmlRpc::XmlRpcValue::TypeDouble:
      return fullPrecisionText(static_cast<double>(value));
    case XmlRpc::XmlRpcValue::TypeInt:
      return std::to_string(static_cast<int>(value));
    case XmlRpc::XmlRpcValue::TypeBoolean:
      return static_cast<bool>(value) ? "true" : "false";
    case XmlRpc::XmlRpcValue::TypeString:
      return static_cast<std::string>(value);
    default:
      return "<not a scalar>";
  }
}

void flatten(XmlRpc::XmlRpcValue& value, const std::string& prefix, FlatConfig& out)
{
  if (value.getType() == XmlRpc::XmlRpcValue::TypeStruct)
  {
    for (auto& item : value)
      flatten(item.second, prefix.empty() ? item.first : prefix + "." + item.first, out);
    return;
  }
  if (value.getType() == XmlRpc::XmlRpcValue::TypeArray)
  {
    // A list of numbers (cam.offset_m: [x, y]): its text, parsed by the setting's type as in config_io.
    std::string text = "[";
    for (int i = 0; i < value.size(); ++i)
      text += (i ? ", " : "") + scalarText(value[i]);
    out[prefix] = ConfigValue{text + "]", "parameter " + prefix};
    return;
  }
  out[prefix] = ConfigValue{scalarText(value), "parameter " + prefix};
}
}  // namespace

ChainConfig chainConfigFromParams(const ros::NodeHandle& nh)
{
  FlatConfig flat;
  XmlRpc::XmlRpcValue tree;
  if (nh.getParam("config", tree))
    flatten(tree, "", flat);
  std::string overrides;
  nh.getParam("config_overrides", overrides);
  std::istringstream words(overrides);
  for (std::string assignment; words >> assignment;)
    applyOverride(flat, assignment);
  return chainConfigFromFlat(flat);
}

std::unique_ptr<OpticalModel> opticalModelFromParams(const ros::NodeHandle& nh, const OpticsConfig& config)
{
  std::string urdf;
  if (!nh.getParam("robot_description", urdf))
    throw InputError("parameter robot_description is not set: load urdf/scanhead.urdf into it (see launch/)");
  auto model = std::make_unique<OpticalModel>(geometryFromUrdf(urdf, nh.resolveName("robot_description")), config);
  // robot_description must be the machine optics.urdf_path + optics.defects name (the launch
  // file's urdf:= and defects:= set both): every frame and the joint range, to 1e-12.
  const OpticalGeometry& got = model->geometry();
  const OpticalGeometry want = loadOpticalModel(config).geometry();
  const Eigen::Isometry3d OpticalGeometry::*frames[] = {
      &OpticalGeometry::source,   &OpticalGeometry::mount_x,  &OpticalGeometry::mirror_x, &OpticalGeometry::mount_y,
      &OpticalGeometry::mirror_y, &OpticalGeometry::window_1, &OpticalGeometry::window_2, &OpticalGeometry::work_plane};
  double worst = std::max(std::abs(got.joint_lower_rad - want.joint_lower_rad),
                          std::abs(got.joint_upper_rad - want.joint_upper_rad));
  for (const auto frame : frames)
    worst = std::max(worst, ((got.*frame).matrix() - (want.*frame).matrix()).cwiseAbs().maxCoeff());
  if (worst > 1e-12)
  {
    throw InputError("robot_description is not the machine optics.urdf_path = '" + config.urdf_path +
                     "' with optics.defects = '" + config.defects + "' (frames differ by " + std::to_string(worst) +
                     "): launch with urdf:= and defects:=, which set both");
  }
  return model;
}
}  // namespace scanhead
