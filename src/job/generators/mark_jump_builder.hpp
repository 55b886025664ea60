/// \file mark_jump_builder.hpp
/// \brief (private to the generators) Appends marks to a Job with the explicit jumps between them.
#pragma once

#include <string>
#include <vector>

#include "scanhead/job/generators/scan_generators.hpp"

namespace scanhead
{
/// \brief Builds a Job from marks: consecutive duplicate points dropped, marks shorter than
/// kMinMarkLength_m dropped, a two-point JUMP inserted before every mark that does not start where
/// the previous one ended.
class MarkJumpBuilder
{
public:
  static constexpr double kMinMarkLength_m = 1e-9;

  MarkJumpBuilder(const HatchStyle& style, std::string name, std::string source);

  /// \brief Appends a MARK through \p points (jump first if needed).
  void mark(const std::vector<Eigen::Vector2d>& points);
  void mark(const Eigen::Vector2d& from, const Eigen::Vector2d& to);

  /// \brief Role of the marks appended from now on (Hatch until set).
  void setRole(PolylineRole role) { role_ = role; }

  bool empty() const { return job_.polylines.empty(); }
  /// \brief End of the last mark (undefined when empty()).
  const Eigen::Vector2d& position() const { return job_.polylines.back().points.back(); }

  Job take() { return std::move(job_); }

private:
  Job job_;
  double mark_speed_mps_;
  double jump_speed_mps_;
  double power_w_;
  PolylineRole role_ = PolylineRole::Hatch;
  std::vector<Eigen::Vector2d> scratch_;
};
}  // namespace scanhead
