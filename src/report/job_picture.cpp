/// \file job_picture.cpp
/// \brief Job picture: a distance-based anti-aliased line rasteriser into coverage buffers,
/// composited marks over jumps over white.
#include "scanhead/report/job_picture.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "scanhead/common/config_check.hpp"
#include "scanhead/report/png_writer.hpp"

namespace scanhead
{
namespace
{
constexpr int kMinSide_px = 16;
constexpr int kMaxSide_px = 8192;

/// Coverage of one layer (marks, jumps or dots), one byte per pixel (255 = full), max over primitives.
class Coverage
{
public:
  Coverage(int width, int height)
    : width_(width)
    , height_(height)
    , c_(static_cast<std::size_t>(width) * static_cast<std::size_t>(height), 0)
  {
  }

  float at(int x, int y) const { return c_[static_cast<std::size_t>(y) * width_ + x] * (1.0f / 255.0f); }

  /// Segment a→b [px] of width 2·(r − 1/2); dashes of \p dash_on every \p dash_period along the
  /// arc length, which is \p s0 at a (dash_period <= 0: solid).
  void segment(const Eigen::Vector2d& a, const Eigen::Vector2d& b, double r, double s0, double dash_on,
               double dash_period)
  {
    const Eigen::Vector2d d = b - a;
    const double len2 = d.squaredNorm();
    if (!(len2 > 1e-18))
    {
      return;
    }
    const double len = std::sqrt(len2);
    const bool major_x = std::abs(d.x()) >= std::abs(d.y());
    const int mj = major_x ? 0 : 1;  // major axis
    const int mn = 1 - mj;           // minor axis
    const double lo = std::min(a[mj], b[mj]);
    const double hi = std::max(a[mj], b[mj]);
    const int limit_major = major_x ? width_ : height_;
    const int limit_minor = major_x ? height_ : width_;
    const int i0 = std::max(0, static_cast<int>(std::ceil(lo - r)));
    const int i1 = std::min(limit_major - 1, static_cast<int>(std::floor(hi + r)));
    const double slope = d[mn] / d[mj];
    // A pixel within r of the segment lies within 2r of the segment's minor coordinate at the
    // clamped major coordinate (|slope| <= 1), so ±(2r + 1) covers it.
    const double span = 2.0 * r + 1.0;
    for (int i = i0; i <= i1; ++i)
    {
      const double m_clamped = std::min(std::max(static_cast<double>(i), lo), hi);
      const double centre = a[mn] + (m_clamped - a[mj]) * slope;
      const int j0 = std::max(0, static_cast<int>(std::ceil(centre - span)));
      const int j1 = std::min(limit_minor - 1, static_cast<int>(std::floor(centre + span)));
      for (int j = j0; j <= j1; ++j)
      {
        Eigen::Vector2d p;
        p[mj] = i;
        p[mn] = j;
        const double t = std::min(1.0, std::max(0.0, (p - a).dot(d) / len2));
        const double dist = (p - (a + t * d)).norm();
        double cov = r - dist;
        if (cov <= 0.0)
        {
          continue;
        }
        if (dash_period > 0.0 && std::fmod(s0 + t * len, dash_period) >= dash_on)
        {
          continue;
        }
        const int x = major_x ? i : j;
        const int y = major_x ? j : i;
        raise(x, y, cov);
      }
    }
  }

  /// Disc of radius \p radius [px] centred on \p p.
  void dot(const Eigen::Vector2d& p, double radius)
  {
    const double r = radius + 0.5;
    const int x0 = std::max(0, static_cast<int>(std::ceil(p.x() - r)));
    const int x1 = std::min(width_ - 1, static_cast<int>(std::floor(p.x() + r)));
    const int y0 = std::max(0, static_cast<int>(std::ceil(p.y() - r)));
    const int y1 = std::min(height_ - 1, static_cast<int>(std::floor(p.y() + r)));
    for (int y = y0; y <= y1; ++y)
    {
      for (int x = x0; x <= x1; ++x)
      {
        const double cov = std::min(1.0, r - (Eigen::Vector2d(x, y) - p).norm());
        if (cov > 0.0)
        {
          raise(x, y, cov);
        }
      }
    }
  }

private:
  void raise(int x, int y, double cov)
  {
    const auto q = static_cast<std::uint8_t>(std::lround(255.0 * std::min(cov, 1.0)));
    std::uint8_t& c = c_[static_cast<std::size_t>(y) * width_ + x];
    c = std::max(c, q);
  }

  int width_;
  int height_;
  std::vector<std::uint8_t> c_;
};

void blend(std::uint8_t* px, const std::array<std::uint8_t, 3>& rgb, float cov)
{
  if (cov <= 0.0f)
  {
    return;
  }
  for (int k = 0; k < 3; ++k)
  {
    const double v = px[k] * (1.0 - cov) + rgb[k] * static_cast<double>(cov);
    px[k] = static_cast<std::uint8_t>(std::lround(std::min(255.0, std::max(0.0, v))));
  }
}
}  // namespace

JobPictureFrame jobPictureFrame(const Job& job, int max_side_px, int margin_px)
{
  if (!(max_side_px >= kMinSide_px && max_side_px <= kMaxSide_px))
  {
    failSetting("job_picture.max_side_px", "in [16, 8192]", max_side_px);
  }
  const int margin = margin_px < 0 ? std::max(2, max_side_px / 40) : margin_px;
  if (!(max_side_px - 1 - 2 * margin >= 4))
  {
    failSetting("job_picture.margin_px", "<= (max_side_px - 5) / 2", margin);
  }
  bool has = false;
  Eigen::Vector2d lo = Eigen::Vector2d::Zero();
  Eigen::Vector2d hi = Eigen::Vector2d::Zero();
  for (const Polyline& line : job.polylines)
  {
    for (const Eigen::Vector2d& p : line.points)
    {
      if (!p.allFinite())
      {
        continue;
      }
      lo = has ? lo.cwiseMin(p) : p;
      hi = has ? hi.cwiseMax(p) : p;
      has = true;
    }
  }
  JobPictureFrame f;
  f.margin_px = margin;
  const double usable = max_side_px - 1 - 2 * margin;
  if (!has)
  {
    f.width = f.height = max_side_px;
    f.scale_px_per_m = usable / 1e-3;
    f.min_m = Eigen::Vector2d::Zero();
    return f;
  }
  Eigen::Vector2d extent = hi - lo;
  double longest = extent.maxCoeff();
  if (!(longest > 0.0))
  {
    lo -= Eigen::Vector2d(0.5e-3, 0.5e-3);
    extent = Eigen::Vector2d(1e-3, 1e-3);
    longest = 1e-3;
  }
  f.min_m = lo;
  f.scale_px_per_m = usable / longest;
  f.width = std::min(max_side_px, static_cast<int>(std::lround(extent.x() * f.scale_px_per_m)) + 1 + 2 * margin);
  f.height = std::min(max_side_px, static_cast<int>(std::lround(extent.y() * f.scale_px_per_m)) + 1 + 2 * margin);
  return f;
}

RgbImage renderJobPicture(const Job& job, int max_side_px)
{
  return renderJobPicture(job, max_side_px, JobPictureOptions());
}

RgbImage renderJobPicture(const Job& job, int max_side_px, const JobPictureOptions& o)
{
  requireSetting(o.mark_width_px > 0.0 && o.mark_width_px <= 100.0, "job_picture.mark_width_px", "in (0, 100]",
                 o.mark_width_px);
  requireSetting(o.jump_width_px > 0.0 && o.jump_width_px <= 100.0, "job_picture.jump_width_px", "in (0, 100]",
                 o.jump_width_px);
  requireSetting(std::isfinite(o.jump_dash_px), "job_picture.jump_dash_px", "finite", o.jump_dash_px);
  requireSetting(o.jump_dash_px <= 0.0 || o.jump_gap_px >= 0.0, "job_picture.jump_gap_px", ">= 0", o.jump_gap_px);
  const JobPictureFrame f = jobPictureFrame(job, max_side_px, o.margin_px);
  Coverage marks(f.width, f.height);
  Coverage jumps(f.width, f.height);
  Coverage starts(f.width, f.height);
  const double r_mark = 0.5 * o.mark_width_px + 0.5;
  const double r_jump = 0.5 * o.jump_width_px + 0.5;
  const bool dashed = o.jump_dash_px > 0.0;
  const double dash_on = o.jump_dash_px;
  const double dash_period = dashed ? o.jump_dash_px + o.jump_gap_px : 0.0;

  bool has_current = false;
  Eigen::Vector2d current = Eigen::Vector2d::Zero();  // [px]
  for (const Polyline& line : job.polylines)
  {
    if (line.points.empty())
    {
      continue;
    }
    const bool mark = line.type == PolylineType::Mark;
    const Eigen::Vector2d first = f.toPixel(line.points.front());
    if (has_current && o.show_jumps && first.allFinite())
    {
      jumps.segment(current, first, r_jump, 0.0, dash_on, dash_period);  // implicit jump (if any length)
    }
    if (mark && o.show_start_points)
    {
      starts.dot(first, 2.0);
    }
    if (mark && line.dwell_s > 0.0 && first.allFinite())
    {
      marks.dot(first, 0.5 * o.mark_width_px + 1.0);  // a spot: a dot a little wider than a mark line
    }
    double s = 0.0;  // arc length along the polyline [px], for the dashes
    for (std::size_t v = 0; v + 1 < line.points.size(); ++v)
    {
      const Eigen::Vector2d a = f.toPixel(line.points[v]);
      const Eigen::Vector2d b = f.toPixel(line.points[v + 1]);
      if (!a.allFinite() || !b.allFinite())
      {
        continue;
      }
      if (mark)
      {
        marks.segment(a, b, r_mark, 0.0, 0.0, 0.0);
      }
      else if (o.show_jumps)
      {
        jumps.segment(a, b, r_jump, s, dash_on, dash_period);
      }
      s += (b - a).norm();
    }
    current = f.toPixel(line.points.back());
    has_current = current.allFinite();
  }

  RgbImage img(f.width, f.height);
  std::fill(img.rgb.begin(), img.rgb.end(), std::uint8_t{255});
  for (int y = 0; y < f.height; ++y)
  {
    for (int x = 0; x < f.width; ++x)
    {
      std::uint8_t* px = img.pixel(x, y);
      blend(px, o.jump_rgb, jumps.at(x, y));
      blend(px, o.mark_rgb, marks.at(x, y));
      blend(px, o.start_rgb, starts.at(x, y));
    }
  }
  return img;
}

void writeJobPicture(const std::string& path, const Job& job, int max_side_px)
{
  writePng(path, renderJobPicture(job, max_side_px));
}
}  // namespace scanhead
