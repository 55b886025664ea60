/// \file thesis_square_job.cpp
/// \brief The THESIS square job (SPEC §5, THESIS §2.5.1) and its recipes.
#include "scanhead/job/generators/thesis_square_job.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "scanhead/common/config_check.hpp"
#include "scanhead/job/job_stats.hpp"

namespace scanhead
{
namespace
{
constexpr double kMaxHatchLines = 1e6;  ///< per square; guards against absurd spacings
constexpr double kMaxSquares = 1e6;

using Points = std::vector<Eigen::Vector2d>;

/// Closed square of half side \p half centred on \p c, from its bottom-right corner, counter-clockwise.
Points squareContour(const Eigen::Vector2d& c, double half)
{
  return {c + Eigen::Vector2d(half, -half), c + Eigen::Vector2d(half, half), c + Eigen::Vector2d(-half, half),
          c + Eigen::Vector2d(-half, -half), c + Eigen::Vector2d(half, -half)};
}

/// Hatch lines x − y = c_k (local frame, square [−h, h]²), c_k decreasing from near the bottom-right
/// corner (c = 2h) to near the top-left corner (c = −2h), every spacing·√2 in c, centred.
std::vector<double> hatchOffsets(double half, double spacing_m)
{
  const double diagonal = 2.0 * half * std::sqrt(2.0);  // extent of the square across the lines
  const double ratio = diagonal / spacing_m;
  // n lines span (n − 1)·spacing; n = round(diagonal / spacing) leaves about spacing/2 at each
  // corner, and (n − 1)·spacing < diagonal always, so every line has a positive length.
  const long n = std::max(1L, std::lround(ratio));
  std::vector<double> c(static_cast<std::size_t>(n));
  const double dc = spacing_m * std::sqrt(2.0);
  for (long k = 0; k < n; ++k)
  {
    c[static_cast<std::size_t>(k)] = (0.5 * static_cast<double>(n - 1) - static_cast<double>(k)) * dc;
  }
  return c;
}

/// The two ends of the line x − y = c inside [−h, h]²: (low, high) with low the lower-left end.
void hatchEnds(double half, double c, Eigen::Vector2d& low, Eigen::Vector2d& high)
{
  if (c >= 0.0)
  {
    low = Eigen::Vector2d(-half + c, -half);  // bottom edge
    high = Eigen::Vector2d(half, half - c);   // right edge
  }
  else
  {
    low = Eigen::Vector2d(-half, -half - c);  // left edge
    high = Eigen::Vector2d(half + c, half);   // top edge
  }
}

Polyline makeLine(PolylineType type, double speed_mps, double power_w, Points points,
                  PolylineRole role = PolylineRole::Unspecified)
{
  Polyline p;
  p.type = type;
  p.speed_mps = speed_mps;
  p.power_w = type == PolylineType::Mark ? power_w : 0.0;
  p.role = role;
  p.points = std::move(points);
  return p;
}
}  // namespace

void SquareJobParams::validate() const
{
  const std::string f = "square_job.";
  if (!(rows >= 1))
    failSetting(f + "rows", ">= 1", rows);
  if (!(columns >= 1))
    failSetting(f + "columns", ">= 1", columns);
  if (!(static_cast<double>(rows) * static_cast<double>(columns) <= kMaxSquares))
    failSetting(f + "rows", "such that rows·columns <= 1e6", rows);
  requireSetting(side_m > 0.0, f + "side_m", "> 0", side_m);
  requireSetting(gap_m >= 0.0, f + "gap_m", ">= 0", gap_m);
  requireSetting(std::isfinite(centre_x_m), f + "centre_x_m", "finite", centre_x_m);
  requireSetting(std::isfinite(centre_y_m), f + "centre_y_m", "finite", centre_y_m);
  requireSetting(contour_offset_m >= 0.0, f + "contour_offset_m", ">= 0", contour_offset_m);
  requireSetting(hatch_inset_m >= 0.0, f + "hatch_inset_m", ">= 0", hatch_inset_m);
  requireSetting(2.0 * (contour_offset_m + hatch_inset_m) < side_m, f + "contour_offset_m",
                 "such that 2·(contour_offset_m + hatch_inset_m) < side_m", contour_offset_m);
  requireSetting(hatch_spacing_m > 0.0, f + "hatch_spacing_m", "> 0", hatch_spacing_m);
  const double hatch_side = side_m - 2.0 * (contour_offset_m + hatch_inset_m);
  requireSetting(hatch_side * std::sqrt(2.0) / hatch_spacing_m <= kMaxHatchLines, f + "hatch_spacing_m",
                 "such that a square has at most 1e6 hatch lines", hatch_spacing_m);
  requireSetting(contour_power_w >= 0.0, f + "contour_power_w", ">= 0", contour_power_w);
  requireSetting(hatch_power_w >= 0.0, f + "hatch_power_w", ">= 0", hatch_power_w);
}

void SquareRecipe::validate() const
{
  const std::string f = "square_recipe.";
  requireSetting(contour_mark_speed_mps > 0.0, f + "contour_mark_speed_mps", "> 0", contour_mark_speed_mps);
  requireSetting(hatch_mark_speed_mps > 0.0, f + "hatch_mark_speed_mps", "> 0", hatch_mark_speed_mps);
  requireSetting(contour_jump_speed_mps > 0.0, f + "contour_jump_speed_mps", "> 0", contour_jump_speed_mps);
  requireSetting(jump_speed_mps > 0.0, f + "jump_speed_mps", "> 0", jump_speed_mps);
}

SquareRecipe thesisRecipe(int recipe)
{
  SquareRecipe r;
  switch (recipe)
  {
    case 1:
      r.contour_mark_speed_mps = 1.5;
      r.hatch_mark_speed_mps = 1.0;
      r.contour_jump_speed_mps = 4.5;
      r.jump_speed_mps = 6.0;
      break;
    case 2:
      r.contour_mark_speed_mps = 1.5;
      r.hatch_mark_speed_mps = 1.5;
      r.contour_jump_speed_mps = 6.0;
      r.jump_speed_mps = 6.0;
      break;
    case 3:
      r.contour_mark_speed_mps = 3.0;
      r.hatch_mark_speed_mps = 3.0;
      r.contour_jump_speed_mps = 12.0;
      r.jump_speed_mps = 12.0;
      break;
    default:
      failSetting("square_job.recipe", "1, 2 or 3", recipe);
  }
  return r;
}

SquareJob makeSquareJob(const SquareJobParams& params, const SquareRecipe& recipe)
{
  params.validate();
  recipe.validate();
  const double pitch = params.pitch_m();
  const double outer_half = 0.5 * params.side_m;
  const double inner_half = outer_half - params.contour_offset_m;
  const double hatch_half = inner_half - params.hatch_inset_m;
  const std::vector<double> offsets = hatchOffsets(hatch_half, params.hatch_spacing_m);

  SquareJob out;
  out.square_count = params.rows * params.columns;
  out.job.name = "thesis_squares";
  out.job.source =
      "built-in: THESIS §2.5.1 square grid " + std::to_string(params.rows) + "x" + std::to_string(params.columns);
  Job& job = out.job;
  auto add = [&](int square, Polyline line) {
    job.polylines.push_back(std::move(line));
    out.square_of_polyline.push_back(square);
  };

  bool first = true;
  Eigen::Vector2d current = Eigen::Vector2d::Zero();
  for (int row = 0; row < params.rows; ++row)
  {
    for (int from_right = 0; from_right < params.columns; ++from_right)
    {
      const int square = row * params.columns + from_right;
      const int col_from_left = params.columns - 1 - from_right;
      const Eigen::Vector2d centre(params.centre_x_m + (col_from_left - 0.5 * (params.columns - 1)) * pitch,
                                   params.centre_y_m + (row - 0.5 * (params.rows - 1)) * pitch);

      const Points inner = squareContour(centre, inner_half);
      const Points outer = squareContour(centre, outer_half);
      if (!first)
      {
        // small jump along a row, long jump to the next row (THESIS Fig. 2.66)
        add(square, makeLine(PolylineType::Jump, recipe.jump_speed_mps, 0.0, {current, inner.front()}));
      }
      first = false;
      add(square, makeLine(PolylineType::Mark, recipe.contour_mark_speed_mps, params.contour_power_w, inner,
                           PolylineRole::Contour));
      add(square, makeLine(PolylineType::Jump, recipe.contour_jump_speed_mps, 0.0, {inner.back(), outer.front()}));
      add(square, makeLine(PolylineType::Mark, recipe.contour_mark_speed_mps, params.contour_power_w, outer,
                           PolylineRole::Contour));

      // Serpentine: line k runs low→high for even k, high→low for odd k, so the connectors lie on
      // the right/top edges after even lines and on the bottom/left edges after odd ones.
      Points hatch;
      hatch.reserve(2 * offsets.size());
      for (std::size_t k = 0; k < offsets.size(); ++k)
      {
        Eigen::Vector2d low, high;
        hatchEnds(hatch_half, offsets[k], low, high);
        if (k % 2 == 0)
        {
          hatch.push_back(centre + low);
          hatch.push_back(centre + high);
        }
        else
        {
          hatch.push_back(centre + high);
          hatch.push_back(centre + low);
        }
      }
      add(square, makeLine(PolylineType::Jump, recipe.jump_speed_mps, 0.0, {outer.back(), hatch.front()}));
      if (!params.hatch_jumps_between_lines)
      {
        add(square, makeLine(PolylineType::Mark, recipe.hatch_mark_speed_mps, params.hatch_power_w, hatch,
                             PolylineRole::Hatch));
      }
      else
      {
        for (std::size_t k = 0; k < offsets.size(); ++k)
        {
          if (k > 0)
          {
            add(square, makeLine(PolylineType::Jump, recipe.jump_speed_mps, 0.0, {hatch[2 * k - 1], hatch[2 * k]}));
          }
          add(square, makeLine(PolylineType::Mark, recipe.hatch_mark_speed_mps, params.hatch_power_w,
                               {hatch[2 * k], hatch[2 * k + 1]}, PolylineRole::Hatch));
        }
      }
      current = hatch.back();
    }
  }
  return out;
}

Job makeThesisSquareJob(const SquareJobParams& params, int recipe)
{
  return makeSquareJob(params, thesisRecipe(recipe)).job;
}

std::vector<double> squareTimes(const SquareJob& square_job)
{
  // Every polyline starts where the previous one ended, so the implicit jump speed is never used.
  const JobStats stats = computeJobStats(square_job.job, 1.0, square_job.square_of_polyline);
  std::vector<double> times(static_cast<std::size_t>(square_job.square_count), 0.0);
  for (std::size_t i = 0; i < stats.groups.size() && i < times.size(); ++i)
  {
    times[i] = stats.groups[i].time_s;
  }
  return times;
}
}  // namespace scanhead
