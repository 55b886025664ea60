/// \file track_energy.cpp
/// \brief Energy density sampled along the actual spot path (SPEC §5, the corner test of NC §4).
#include "scanhead/energy/track_energy.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "scanhead/common/config_check.hpp"
#include "scanhead/common/errors.hpp"

namespace scanhead
{
namespace
{
/// \brief Lower pixel index and weight of the upper one along one axis; \p u in pixel-centre
/// coordinates (centres at integers), clamped to [0, n − 1].
inline void axisWeights(double u, std::int64_t n, std::int64_t& i0, std::int64_t& i1, double& a)
{
  const double hi = static_cast<double>(n - 1);
  u = std::min(std::max(u, 0.0), hi);
  const double f = std::floor(u);
  i0 = static_cast<std::int64_t>(f);
  i1 = std::min(i0 + 1, n - 1);
  a = u - f;
}

/// \brief Bilinear E between pixel centres; 0 off the map (see the header for the edge band).
template <class Map>
double bilinear(const Map& map, const Eigen::Vector2d& p)
{
  const double pixel = map.pixel();
  const double x = (p.x() - map.origin().x()) / pixel;  // [pixels] from the map's corner
  const double y = (p.y() - map.origin().y()) / pixel;
  if (!(x >= 0.0 && x <= static_cast<double>(map.width()) && y >= 0.0 && y <= static_cast<double>(map.height())))
  {
    return 0.0;
  }
  std::int64_t i0, i1, j0, j1;
  double a, b;
  axisWeights(x - 0.5, map.width(), i0, i1, a);
  axisWeights(y - 0.5, map.height(), j0, j1, b);
  return (1.0 - a) * (1.0 - b) * map.at(i0, j0) + a * (1.0 - b) * map.at(i1, j0) + (1.0 - a) * b * map.at(i0, j1) +
         a * b * map.at(i1, j1);
}
}  // namespace

namespace
{
/// \brief Whether \p p lies within \p radius of a point of \p ends_by_x (sorted by x).
bool nearAnEnd(const Eigen::Vector2d& p, const std::vector<Eigen::Vector2d>& ends_by_x, double radius)
{
  auto it = std::lower_bound(ends_by_x.begin(), ends_by_x.end(), p.x() - radius,
                             [](const Eigen::Vector2d& e, double x) { return e.x() < x; });
  for (; it != ends_by_x.end() && it->x() <= p.x() + radius; ++it)
  {
    if ((*it - p).norm() <= radius)
      return true;
  }
  return false;
}
}  // namespace

namespace
{
template <class Map>
TrackEnergyProfile profileOn(const Map& map, const std::vector<SpotSample>& spots, double exclude_ends_m,
                             const std::vector<Eigen::Vector2d>* track_ends)
{
  std::vector<Eigen::Vector2d> ends_by_x;
  if (track_ends)
  {
    ends_by_x = *track_ends;
    std::sort(ends_by_x.begin(), ends_by_x.end(),
              [](const Eigen::Vector2d& a, const Eigen::Vector2d& b) { return a.x() < b.x(); });
  }
  requireSetting(exclude_ends_m >= 0.0, "track_energy.exclude_ends_m", ">= 0", exclude_ends_m);
  TrackEnergyProfile out;
  std::size_t on = 0;
  for (const SpotSample& s : spots)
  {
    on += s.power_w > 0.0 ? 1 : 0;
  }
  out.arc_m.reserve(on);
  out.energy_jpm2.reserve(on);
  out.interior.assign(on, 0);
  std::vector<const Eigen::Vector2d*> where;  // actual spot of each laser-on sample
  where.reserve(on);

  // Pass 1: energy and arc of every laser-on sample.
  double arc = 0.0;
  bool previous_on = false;
  for (std::size_t k = 0; k < spots.size(); ++k)
  {
    const SpotSample& s = spots[k];
    if (!(s.power_w > 0.0))
    {
      previous_on = false;
      continue;
    }
    if (!s.actual.allFinite())
    {
      std::ostringstream msg;
      msg << "track energy: non-finite actual spot (" << s.actual.x() << ", " << s.actual.y() << ") m at sample " << k
          << " while the laser is on";
      throw NumericalError(msg.str());
    }
    if (previous_on)
    {
      arc += (s.actual - spots[k - 1].actual).norm();
    }
    previous_on = true;
    out.arc_m.push_back(arc);
    out.energy_jpm2.push_back(bilinear(map, s.actual));
    where.push_back(&s.actual);
  }

  // Pass 2: bursts (runs of laser-on samples consecutive in the stream), interior flags.
  std::vector<double> interior_values;
  interior_values.reserve(on);
  double sum = 0.0;
  std::size_t m = 0;  // index among laser-on samples
  for (std::size_t k = 0; k < spots.size();)
  {
    if (!(spots[k].power_w > 0.0))
    {
      ++k;
      continue;
    }
    std::size_t end = k;  // one past the burst in spots
    while (end < spots.size() && spots[end].power_w > 0.0)
    {
      ++end;
    }
    const std::size_t first = m, last = m + (end - k) - 1;
    const double arc_first = out.arc_m[first], arc_last = out.arc_m[last];
    for (std::size_t q = first; q <= last; ++q)
    {
      const double s = out.arc_m[q];
      const bool interior = track_ends ? !nearAnEnd(*where[q], ends_by_x, exclude_ends_m)
                                       : (s - arc_first > exclude_ends_m && arc_last - s > exclude_ends_m);
      if (interior)
      {
        out.interior[q] = 1;
        const double e = out.energy_jpm2[q];
        interior_values.push_back(e);
        sum += e;
        if (out.interior_samples == 0 || e < out.min_jpm2)
        {
          out.min_jpm2 = e;
        }
        if (out.interior_samples == 0 || e > out.peak_jpm2)
        {
          out.peak_jpm2 = e;
          out.peak_point_m = *where[q];
        }
        ++out.interior_samples;
      }
    }
    m = last + 1;
    k = end;
  }

  const std::size_t n = interior_values.size();
  if (n > 0)
  {
    out.mean_jpm2 = sum / static_cast<double>(n);
    const auto mid = interior_values.begin() + static_cast<std::ptrdiff_t>(n / 2);
    std::nth_element(interior_values.begin(), mid, interior_values.end());
    double median = *mid;
    if (n % 2 == 0)
    {
      // The lower middle value is the largest of the part before mid.
      median = 0.5 * (median + *std::max_element(interior_values.begin(), mid));
    }
    out.median_jpm2 = median;
  }
  return out;
}
}  // namespace

TrackEnergyProfile trackEnergyProfile(const EnergyMap& map, const std::vector<SpotSample>& spots, double exclude_ends_m,
                                      const std::vector<Eigen::Vector2d>* track_ends)
{
  return profileOn(map, spots, exclude_ends_m, track_ends);
}

TrackEnergyProfile trackEnergyProfile(const TiledEnergyMap& map, const std::vector<SpotSample>& spots,
                                      double exclude_ends_m, const std::vector<Eigen::Vector2d>* track_ends)
{
  return profileOn(map, spots, exclude_ends_m, track_ends);
}

double peakNear(const TiledEnergyMap& map, const Eigen::Vector2d& point, double radius_m)
{
  const double p = map.pixel();
  const double u = (point.x() - map.origin().x()) / p, v = (point.y() - map.origin().y()) / p;
  const double r = radius_m / p;
  double peak = map.at(static_cast<std::int64_t>(std::floor(u)), static_cast<std::int64_t>(std::floor(v)));
  for (auto row = static_cast<std::int64_t>(std::floor(v - r - 0.5));
       row <= static_cast<std::int64_t>(std::ceil(v + r)); ++row)
    for (auto col = static_cast<std::int64_t>(std::floor(u - r - 0.5));
         col <= static_cast<std::int64_t>(std::ceil(u + r)); ++col)
    {
      const double dx = static_cast<double>(col) + 0.5 - u, dy = static_cast<double>(row) + 0.5 - v;
      if (dx * dx + dy * dy <= r * r)
        peak = std::max(peak, static_cast<double>(map.at(col, row)));
    }
  return peak;
}

std::vector<double> peaksNear(const TiledEnergyMap& map, const std::vector<Eigen::Vector2d>& points,
                              const std::vector<double>& radii_m, const std::function<void()>& during)
{
  // Each disc as in peakNear: the pixel holding the point, and the pixels whose centre lies within r.
  struct Disc
  {
    double u = 0.0, v = 0.0, r = 0.0;
    std::int64_t col0 = 0, col1 = 0, row0 = 0, row1 = 0, point_col = 0, point_row = 0;
  };
  const double p = map.pixel();
  const std::int64_t side = TiledEnergyMap::kTileSide;
  std::vector<Disc> discs(points.size());
  std::vector<std::pair<std::int64_t, std::uint32_t>> owed;  // (tile, disc), sorted by tile
  for (std::size_t i = 0; i < points.size(); ++i)
  {
    Disc& d = discs[i];
    d.u = (points[i].x() - map.origin().x()) / p;
    d.v = (points[i].y() - map.origin().y()) / p;
    d.r = radii_m[i] / p;
    d.point_col = static_cast<std::int64_t>(std::floor(d.u));
    d.point_row = static_cast<std::int64_t>(std::floor(d.v));
    d.col0 = std::min(d.point_col, static_cast<std::int64_t>(std::floor(d.u - d.r - 0.5)));
    d.col1 = std::max(d.point_col, static_cast<std::int64_t>(std::ceil(d.u + d.r)));
    d.row0 = std::min(d.point_row, static_cast<std::int64_t>(std::floor(d.v - d.r - 0.5)));
    d.row1 = std::max(d.point_row, static_cast<std::int64_t>(std::ceil(d.v + d.r)));
    // Pixels off the map read 0 and E ≥ 0: only the tiles on the map count.
    const std::int64_t c0 = std::max<std::int64_t>(0, d.col0), c1 = std::min(map.width() - 1, d.col1);
    const std::int64_t r0 = std::max<std::int64_t>(0, d.row0), r1 = std::min(map.height() - 1, d.row1);
    for (std::int64_t tr = r0 / side; r0 <= r1 && tr <= r1 / side; ++tr)
      for (std::int64_t tc = c0 / side; c0 <= c1 && tc <= c1 / side; ++tc)
        owed.emplace_back(tr * map.tilesAcross() + tc, static_cast<std::uint32_t>(i));
  }
  std::sort(owed.begin(), owed.end());
  std::vector<double> peaks(points.size(), 0.0);
  std::vector<char> served(owed.size(), 0);
  auto serve = [&](std::int64_t tile, const float* data) {
    auto it = std::lower_bound(owed.begin(), owed.end(), std::make_pair(tile, std::uint32_t{0}));
    const std::int64_t tr = tile / map.tilesAcross(), tc = tile % map.tilesAcross();
    for (; it != owed.end() && it->first == tile; ++it)
    {
      char& done = served[static_cast<std::size_t>(it - owed.begin())];
      if (done)
        return;  // a tile brought back again: its discs were served the first time
      done = 1;
      const Disc& d = discs[it->second];
      double& peak = peaks[it->second];
      const std::int64_t r0 = std::max(d.row0, tr * side), r1 = std::min(d.row1, tr * side + side - 1);
      const std::int64_t c0 = std::max(d.col0, tc * side), c1 = std::min(d.col1, tc * side + side - 1);
      for (std::int64_t row = r0; row <= r1; ++row)
        for (std::int64_t col = c0; col <= c1; ++col)
        {
          const double dx = static_cast<double>(col) + 0.5 - d.u, dy = static_cast<double>(row) + 0.5 - d.v;
          if (dx * dx + dy * dy <= d.r * d.r || (col == d.point_col && row == d.point_row))
            peak = std::max(peak, static_cast<double>(data[(row - tr * side) * side + (col - tc * side)]));
        }
    }
  };
  map.observeBroughtBack(serve);
  try
  {
    during();
  }
  catch (...)
  {
    map.observeBroughtBack(nullptr);
    throw;
  }
  map.observeBroughtBack(nullptr);
  // The tiles still owed (resident all along, or not on the pass's way), in tile order.
  std::vector<float> scratch(static_cast<std::size_t>(side * side));
  for (std::size_t k = 0; k < owed.size(); ++k)
  {
    if (served[k] || (k > 0 && owed[k].first == owed[k - 1].first))
      continue;
    const float* data = map.tileData(owed[k].first, scratch.data());
    if (data != nullptr)
      serve(owed[k].first, data);
  }
  return peaks;
}
}  // namespace scanhead
