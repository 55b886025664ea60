#include "ros_config.hpp"

#include <xmlrpcpp/XmlRpcValue.h>

#include <cstdio>
#include <sstream>

#include "scanhead/core/batch_chain.hpp"
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
  auto model = std::make_unique<OpticalModel>(geometryFromUrdf(urdf, nh.resolveName("robot_description")), config);
  // robot_description must be the machine optics.defects names (the launch file's defects:= sets
  // both): the batch runner builds it from the nominal URDF and the set, the graph from the URDF.
  const OpticalModel expected = loadOpticalModel(config);
  for (const Eigen::Vector2d& q : { Eigen::Vector2d(0.0, 0.0), Eigen::Vector2d(0.1, -0.1), Eigen::Vector2d(-0.12, 0.08) })
  {
    if ((model->spot(q) - expected.spot(q)).norm() > 1e-9)
    {
      throw InputError("robot_description is not the machine optics.defects = '" + config.defects +
                       "' names (spots differ at angles (" + std::to_string(q.x()) + ", " + std::to_string(q.y()) +
                       ") rad): launch with defects:=" + config.defects + ", which generates both");
    }
  }
  return model;
}
}  // namespace scanhead
