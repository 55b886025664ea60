/// \file laser_placement.cpp
/// \brief Laser-on samples off the marked path, with a uniform grid of mark segments (SPEC §2.5).
#include "scanhead/metrics/laser_placement.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "scanhead/common/config_check.hpp"
#include "scanhead/common/errors.hpp"

namespace scanhead
{
namespace
{
constexpr double kMinCellM = 1e-3;       ///< smallest cell side [m] (bounds the cell count)
constexpr double kMaxCells = 4194304.0;  ///< 2^22 cells at most (32 MiB of cell starts)
constexpr double kInf = std::numeric_limits<double>::infinity();

/// \brief Squared distance from (px, py) to the segment a + t·d, t ∈ [0, 1].
template <class Segment>
inline double distance2(const Segment& s, double px, double py)
{
  const double qx = px - s.ax, qy = py - s.ay;
  double t = (qx * s.dx + qy * s.dy) * s.inv_len2;
  t = t < 0.0 ? 0.0 : (t > 1.0 ? 1.0 : t);
  const double ex = qx - t * s.dx, ey = qy - t * s.dy;
  return ex * ex + ey * ey;
}

/// \brief [lo, hi] ∩ [0, n − 1] as integers; false if empty. lo, hi are whole numbers (as doubles).
inline bool clip(double lo, double hi, long n, long& a, long& b)
{
  lo = std::max(lo, 0.0);
  hi = std::min(hi, static_cast<double>(n - 1));
  if (lo > hi)
  {
    return false;
  }
  a = static_cast<long>(lo);
  b = static_cast<long>(hi);
  return true;
}
}  // namespace

LaserPlacement::LaserPlacement(const Job& job, double tolerance_m)
  : tolerance_m_(tolerance_m)
{
  requireSetting(tolerance_m > 0.0, "laser_placement.tolerance_m", "> 0", tolerance_m);

  // Segments of the MARK polylines; a 1-point polyline (dwell) is a zero-length segment.
  Eigen::Vector2d lo(kInf, kInf), hi(-kInf, -kInf);
  auto push = [&](const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    Segment s;
    s.ax = a.x();
    s.ay = a.y();
    s.dx = b.x() - a.x();
    s.dy = b.y() - a.y();
    const double len2 = s.dx * s.dx + s.dy * s.dy;
    const double inv = len2 > 0.0 ? 1.0 / len2 : 0.0;
    s.inv_len2 = std::isfinite(inv) ? inv : 0.0;  // a denormal length: a point (error < 1e-154 m)
    segments_.push_back(s);
  };
  for (std::size_t p = 0; p < job.polylines.size(); ++p)
  {
    const Polyline& line = job.polylines[p];
    if (line.type != PolylineType::Mark)
    {
      continue;
    }
    for (std::size_t k = 0; k < line.points.size(); ++k)
    {
      const Eigen::Vector2d& v = line.points[k];
      if (!v.allFinite())
      {
        std::ostringstream msg;
        msg << "laser placement: polyline " << p << " vertex " << k << " is not finite (" << v.x() << ", " << v.y()
            << ") m";
        throw InputError(msg.str());
      }
      lo = lo.cwiseMin(v);
      hi = hi.cwiseMax(v);
      if (k > 0)
      {
        push(line.points[k - 1], v);
      }
    }
    if (line.points.size() == 1)
    {
      push(line.points[0], line.points[0]);
    }
  }
  if (segments_.empty())
  {
    return;  // no mark: nx_ = ny_ = 0, every distance is infinite
  }
  if (segments_.size() > std::numeric_limits<std::uint32_t>::max())
  {
    throw InputError("laser placement: more than 2^32 mark segments");
  }

  // Grid: origin one cell below the box, floor(L/c) + 4 cells, i.e. up to at least max + 2c, so
  // every tolerance neighbourhood (≤ c) lies inside and a point off the grid is > c from any mark.
  const Eigen::Vector2d extent = hi - lo;
  double c = std::max(tolerance_m, kMinCellM);
  double nx = 0.0, ny = 0.0;
  for (;;)
  {
    nx = std::floor(extent.x() / c) + 4.0;
    ny = std::floor(extent.y() / c) + 4.0;
    if (nx * ny <= kMaxCells)
    {
      break;
    }
    c *= 2.0;
  }
  cell_m_ = c;
  nx_ = static_cast<long>(nx);
  ny_ = static_cast<long>(ny);
  grid_origin_m_ = lo - Eigen::Vector2d(c, c);
  const double ox = grid_origin_m_.x(), oy = grid_origin_m_.y();

  // Cells touched by segment ⊕ [−r, r]², row by row: in row j (y ∈ [Y_j, Y_j + c]) those are the
  // x range of the part of the segment with y ∈ [Y_j − r, Y_j + c + r], widened by r. The 1e-9·c
  // slack absorbs the rounding of the cell arithmetic, so a point within the tolerance of a
  // segment always finds it in its own cell.
  const double r = tolerance_m + 1e-9 * c;
  auto forEachCell = [&](const Segment& s, auto&& visit) {
    const double x0 = std::min(s.ax, s.ax + s.dx), x1 = std::max(s.ax, s.ax + s.dx);
    const double y0 = std::min(s.ay, s.ay + s.dy), y1 = std::max(s.ay, s.ay + s.dy);
    long j0, j1;
    if (!clip(std::floor((y0 - r - oy) / c), std::floor((y1 + r - oy) / c), ny_, j0, j1))
    {
      return;
    }
    for (long j = j0; j <= j1; ++j)
    {
      double xa = x0, xb = x1;
      if (s.dy != 0.0)
      {
        const double band_lo = oy + static_cast<double>(j) * c - r;
        const double band_hi = oy + static_cast<double>(j + 1) * c + r;
        const double t1 = (band_lo - s.ay) / s.dy, t2 = (band_hi - s.ay) / s.dy;
        const double t_lo = std::max(0.0, std::min(t1, t2)), t_hi = std::min(1.0, std::max(t1, t2));
        if (t_lo > t_hi)
        {
          continue;
        }
        xa = s.ax + t_lo * s.dx;
        xb = s.ax + t_hi * s.dx;
        if (xa > xb)
        {
          std::swap(xa, xb);
        }
      }
      long i0, i1;
      if (!clip(std::floor((xa - r - ox) / c), std::floor((xb + r - ox) / c), nx_, i0, i1))
      {
        continue;
      }
      for (long i = i0; i <= i1; ++i)
      {
        visit(static_cast<std::size_t>(j * nx_ + i));
      }
    }
  };

  // Compressed rows: count, prefix sums, fill (segment order inside a cell = job order).
  const std::size_t cells = static_cast<std::size_t>(nx_ * ny_);
  cell_start_.assign(cells + 1, 0);
  for (const Segment& s : segments_)
  {
    forEachCell(s, [&](std::size_t cell) { ++cell_start_[cell + 1]; });
  }
  for (std::size_t k = 0; k < cells; ++k)
  {
    cell_start_[k + 1] += cell_start_[k];
  }
  cell_segments_.resize(cell_start_[cells]);
  std::vector<std::size_t> cursor(cell_start_.begin(), cell_start_.end() - 1);
  for (std::size_t id = 0; id < segments_.size(); ++id)
  {
    forEachCell(segments_[id],
                [&](std::size_t cell) { cell_segments_[cursor[cell]++] = static_cast<std::uint32_t>(id); });
  }
}

void LaserPlacement::searchCells(double px, double py, long i0, long i1, long j0, long j1, double& best,
                                 std::uint32_t& best_id) const
{
  const Segment* segs = segments_.data();
  const std::uint32_t* ids = cell_segments_.data();
  for (long j = j0; j <= j1; ++j)
  {
    const std::size_t row = static_cast<std::size_t>(j * nx_);
    const std::size_t begin = cell_start_[row + static_cast<std::size_t>(i0)];
    const std::size_t end = cell_start_[row + static_cast<std::size_t>(i1) + 1];  // cells i0..i1 are contiguous
    for (std::size_t e = begin; e < end; ++e)
    {
      const double d2 = distance2(segs[ids[e]], px, py);
      if (d2 < best)
      {
        best = d2;
        best_id = ids[e];
      }
    }
  }
}

double LaserPlacement::distanceToMarks(const Eigen::Vector2d& point) const
{
  if (!point.allFinite())
  {
    return std::numeric_limits<double>::quiet_NaN();
  }
  if (segments_.empty())
  {
    return kInf;
  }
  const double fi = std::floor((point.x() - grid_origin_m_.x()) / cell_m_);
  const double fj = std::floor((point.y() - grid_origin_m_.y()) / cell_m_);
  long i0, i1, j0, j1;
  if (!clip(fi - 1.0, fi + 1.0, nx_, i0, i1) || !clip(fj - 1.0, fj + 1.0, ny_, j0, j1))
  {
    return kInf;
  }
  double best = kInf;
  std::uint32_t id = 0;
  searchCells(point.x(), point.y(), i0, i1, j0, j1, best, id);
  const double d = std::sqrt(best);
  return d <= cell_m_ ? d : kInf;  // beyond the reach a nearer segment may sit outside the 3 × 3 cells
}

double LaserPlacement::exactDistance(const Eigen::Vector2d& point, std::uint32_t& id) const
{
  if (segments_.empty())
  {
    return kInf;
  }
  const double px = point.x(), py = point.y();
  const double fi = std::floor((px - grid_origin_m_.x()) / cell_m_);
  const double fj = std::floor((py - grid_origin_m_.y()) / cell_m_);
  const double last_i = static_cast<double>(nx_ - 1), last_j = static_cast<double>(ny_ - 1);
  // Chebyshev distance in cells from the point's cell to the grid.
  const double gap = std::max(fi < 0.0 ? -fi : std::max(0.0, fi - last_i), fj < 0.0 ? -fj : std::max(0.0, fj - last_j));
  double best = kInf;
  if (gap > last_i + last_j + 2.0)
  {
    // Far off the grid (a frame error, not a delay): all segments; no ring arithmetic on huge indices.
    for (std::size_t k = 0; k < segments_.size(); ++k)
    {
      const double d2 = distance2(segments_[k], px, py);
      if (d2 < best)
      {
        best = d2;
        id = static_cast<std::uint32_t>(k);
      }
    }
    return std::sqrt(best);
  }
  // Rings of cells at Chebyshev distance k: once all cells within k are searched, any other
  // segment is at least k·c away, so best ≤ (k·c)² is final.
  double k = std::max(1.0, gap);
  long i0, i1, j0, j1;
  if (clip(fi - k, fi + k, nx_, i0, i1) && clip(fj - k, fj + k, ny_, j0, j1))
  {
    searchCells(px, py, i0, i1, j0, j1, best, id);
  }
  for (;;)
  {
    const double reach = k * cell_m_;
    if (best <= reach * reach || (fi - k <= 0.0 && fi + k >= last_i && fj - k <= 0.0 && fj + k >= last_j))
    {
      return std::sqrt(best);
    }
    k += 1.0;
    if (clip(fi - k, fi + k, nx_, i0, i1))
    {
      if (clip(fj - k, fj - k, ny_, j0, j1))
        searchCells(px, py, i0, i1, j0, j1, best, id);  // bottom row of the ring
      if (clip(fj + k, fj + k, ny_, j0, j1))
        searchCells(px, py, i0, i1, j0, j1, best, id);  // top row
    }
    if (clip(fj - k + 1.0, fj + k - 1.0, ny_, j0, j1))
    {
      if (clip(fi - k, fi - k, nx_, i0, i1))
        searchCells(px, py, i0, i1, j0, j1, best, id);  // left column
      if (clip(fi + k, fi + k, nx_, i0, i1))
        searchCells(px, py, i0, i1, j0, j1, best, id);  // right column
    }
  }
}

void LaserPlacement::add(const SpotChunk& chunk)
{
  const double ox = grid_origin_m_.x(), oy = grid_origin_m_.y();
  // The lower bound must clear the tolerance by more than the rounding of d(q) − |p − q|.
  const double lower_margin_m = 1e-9 * cell_m_;
  for (std::size_t k = 0; k < chunk.samples.size(); ++k)
  {
    const SpotSample& s = chunk.samples[k];
    if (!(s.power_w > 0.0))
    {
      continue;
    }
    const Eigen::Vector2d& p = s.actual;
    if (!p.allFinite())
    {
      std::ostringstream msg;
      msg << "laser placement: non-finite actual spot (" << p.x() << ", " << p.y() << ") m at sample "
          << chunk.first_index + k << " while the laser is on";
      throw NumericalError(msg.str());
    }
    ++counts_.laser_on_samples;

    // Bounds from the last searched sample q: d(p) ≤ |p − s(q)| (the same arithmetic as a search
    // over s(q), so exact), d(p) ≥ d(q) − |p − q| ≥ lower(q) − |p − q|.
    bool off = false;
    bool settled = false;
    if (has_last_)
    {
      const double upper = std::sqrt(distance2(segments_[last_segment_], p.x(), p.y()));
      const bool max_settled = upper <= counts_.max_distance_m;
      if (upper <= tolerance_m_)
      {
        settled = max_settled;
      }
      else if (last_distance_m_ - (p - last_point_m_).norm() > tolerance_m_ + lower_margin_m)
      {
        off = true;
        settled = max_settled;
      }
    }
    if (!settled)
    {
      // Own cell first: it holds every segment within the tolerance, so if its nearest segment is
      // within the tolerance, that is the nearest of all.
      double d = kInf;
      double lower = 0.0;  // a lower bound of the distance [m]
      std::uint32_t id = 0;
      const double fi = std::floor((p.x() - ox) / cell_m_);
      const double fj = std::floor((p.y() - oy) / cell_m_);
      if (fi >= 0.0 && fi < static_cast<double>(nx_) && fj >= 0.0 && fj < static_cast<double>(ny_))
      {
        const long i = static_cast<long>(fi), j = static_cast<long>(fj);
        double best = kInf;
        searchCells(p.x(), p.y(), i, i, j, j, best, id);
        d = std::sqrt(best);
        // A segment not in this cell is farther than the tolerance from the whole cell.
        const double x0 = ox + fi * cell_m_, y0 = oy + fj * cell_m_;
        const double edge =
            std::min(std::min(p.x() - x0, x0 + cell_m_ - p.x()), std::min(p.y() - y0, y0 + cell_m_ - p.y()));
        lower = std::min(d, tolerance_m_ + std::max(0.0, edge));
      }
      off = !(d <= tolerance_m_);
      if (!off)
      {
        lower = d;  // the own cell's nearest is the nearest of all
      }
      else if (!(d <= counts_.max_distance_m))
      {
        // Off path and maybe a new maximum: the exact distance (otherwise d(p) ≤ d ≤ max already).
        d = exactDistance(p, id);
        lower = d;
      }
      counts_.max_distance_m = std::max(counts_.max_distance_m, d);
      has_last_ = !segments_.empty();
      last_point_m_ = p;
      last_distance_m_ = lower;
      last_segment_ = id;
    }
    if (off)
    {
      ++counts_.off_path_samples;
      counts_.off_path_energy_j += s.power_w * chunk.period_s;
    }
  }
}
}  // namespace scanhead
