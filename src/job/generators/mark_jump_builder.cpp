#include "mark_jump_builder.hpp"

namespace scanhead
{
MarkJumpBuilder::MarkJumpBuilder(const HatchStyle& style, std::string name, std::string source)
  : mark_speed_mps_(style.mark_speed_mps)
  , jump_speed_mps_(style.jump_speed_mps)
  , power_w_(style.power_w)
{
  job_.name = std::move(name);
  job_.source = std::move(source);
}

void MarkJumpBuilder::mark(const std::vector<Eigen::Vector2d>& points)
{
  scratch_.clear();
  double length = 0.0;
  for (const Eigen::Vector2d& p : points)
    if (scratch_.empty() || p != scratch_.back())
    {
      if (!scratch_.empty())
        length += (p - scratch_.back()).norm();
      scratch_.push_back(p);
    }
  if (scratch_.size() < 2 || length < kMinMarkLength_m)
    return;
  if (!job_.polylines.empty() && job_.polylines.back().points.back() != scratch_.front())
  {
    Polyline jump;
    jump.type = PolylineType::Jump;
    jump.speed_mps = jump_speed_mps_;
    jump.power_w = 0.0;
    jump.points = {job_.polylines.back().points.back(), scratch_.front()};
    job_.polylines.push_back(std::move(jump));
  }
  Polyline line;
  line.type = PolylineType::Mark;
  line.role = role_;
  line.speed_mps = mark_speed_mps_;
  line.power_w = power_w_;
  line.points = scratch_;
  job_.polylines.push_back(std::move(line));
}

void MarkJumpBuilder::mark(const Eigen::Vector2d& from, const Eigen::Vector2d& to)
{
  if ((to - from).norm() < kMinMarkLength_m)
    return;
  mark(std::vector<Eigen::Vector2d>{from, to});
}
}  // namespace scanhead
