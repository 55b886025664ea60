#include "ros_config.hpp"

#include <xmlrpcpp/XmlRpcValue.h>

#include <cstdio>
#include <sstream>

#include "scanhead/core/config_io.hpp"
#include "scanhead/core/errors.hpp"
#include "scanhead/core/number_text.hpp"

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
  return std::make_unique<OpticalModel>(geometryFromUrdf(urdf, nh.resolveName("robot_description")), config);
}
}  // namespace scanhead
