/// \file cli_builder.cpp
/// \brief CLI geometry → Job: layer selection, CLI+ speed and power, explicit jumps, units.
#include "cli_internal.hpp"
#include "scanhead/common/errors.hpp"

namespace scanhead
{
namespace cli
{
JobBuilder::JobBuilder(const CliReadOptions& options, double m_per_unit)
  : want_(options.layer)
  , m_per_unit_(m_per_unit)
  , speed_mps_(options.mark_speed_mps)
  , power_w_(options.mark_power_w)
  , jump_speed_mps_(options.jump_speed_mps)
{
  job_.file.begin(options.box_rotation_deg);
}

void JobBuilder::beginMark(std::size_t n_points, PolylineRole role)
{
  current_ = Polyline{};
  current_.type = PolylineType::Mark;
  current_.role = role;
  current_.speed_mps = speed_mps_;
  current_.power_w = power_w_;
  current_.points.reserve(n_points);
}

void JobBuilder::endMark()
{
  if (current_.points.size() < 2)
    return;  // a point or nothing: no path to mark
  const Eigen::Vector2d start = current_.points.front();
  // The survey sees the file as read with every layer (cam.layer = -1): jumps join the layers too.
  const std::size_t layer = static_cast<std::size_t>(layers_ - 1);
  if (has_surveyed_ && start != surveyed_end_)
    job_.file.addTime(layer, (start - surveyed_end_).norm() / jump_speed_mps_);  // its ends are marks' points
  job_.file.add(layer, current_);
  surveyed_end_ = current_.points.back();
  has_surveyed_ = true;
  if (!active_)
    return;
  if (has_last_ && start != last_end_)
  {
    Polyline jump;
    jump.type = PolylineType::Jump;
    jump.speed_mps = jump_speed_mps_;
    jump.power_w = 0.0;
    jump.points = {last_end_, start};
    job_.polylines.push_back(std::move(jump));
  }
  last_end_ = current_.points.back();
  has_last_ = true;
  job_.polylines.push_back(std::move(current_));
  current_ = Polyline{};
}

Job JobBuilder::finish(const std::string& source, long declared_layers)
{
  if (want_ >= layers_)
  {
    std::string msg = source + ": layer " + std::to_string(want_) + " requested, but the file has " +
                      std::to_string(layers_) + " layer" + (layers_ == 1 ? "" : "s");
    if (layers_ > 0)
      msg += " (indices 0.." + std::to_string(layers_ - 1) + " in file order; -1 for all)";
    if (declared_layers >= 0 && declared_layers != layers_)
      msg += "; its header declares $$LAYERS/" + std::to_string(declared_layers);
    throw InputError(msg);
  }
  // Name: the file stem, plus the layer when one was selected.
  const std::size_t slash = source.find_last_of("/\\");
  std::string name = slash == std::string::npos ? source : source.substr(slash + 1);
  const std::size_t dot = name.find_last_of('.');
  if (dot != std::string::npos && dot > 0)
    name.erase(dot);
  if (want_ >= 0)
    name += "_layer" + std::to_string(want_);
  job_.name = name;
  job_.source = source;
  job_.file.finish(static_cast<std::size_t>(layers_));
  return std::move(job_);
}
}  // namespace cli
}  // namespace scanhead
