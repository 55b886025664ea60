/// \file track_energy.cpp
/// \brief Energy density sampled along the actual spot path (SPEC §5, the corner test of NC §4).
#include "scanhead/energy/track_energy.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
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

/// \brief The four pixels and weights of the bilinear E at one point (see the header for the edge band).
struct Bilinear
{
  std::int64_t i0 = 0, i1 = 0, j0 = 0, j1 = 0;
  double a = 0.0, b = 0.0;
  bool on_map = false;  ///< false: the point reads 0

  /// \brief E from the pixels (i0, j0), (i1, j0), (i0, j1), (i1, j1).
  double value(float e00, float e10, float e01, float e11) const
  {
    if (!on_map)
      return 0.0;
    return (1.0 - a) * (1.0 - b) * e00 + a * (1.0 - b) * e10 + (1.0 - a) * b * e01 + a * b * e11;
  }
};

/// \brief The bilinear stencil at \p p on a map of \p width × \p height pixels of side \p pixel from \p origin.
Bilinear bilinearAt(const Eigen::Vector2d& origin, double pixel, std::int64_t width, std::int64_t height,
                    const Eigen::Vector2d& p)
{
  Bilinear w;
  const double x = (p.x() - origin.x()) / pixel;  // [pixels] from the map's corner
  const double y = (p.y() - origin.y()) / pixel;
  w.on_map = x >= 0.0 && x <= static_cast<double>(width) && y >= 0.0 && y <= static_cast<double>(height);
  if (w.on_map)
  {
    axisWeights(x - 0.5, width, w.i0, w.i1, w.a);
    axisWeights(y - 0.5, height, w.j0, w.j1, w.b);
  }
  return w;
}

/// \brief Bilinear E between pixel centres; 0 off the map.
template <class Map>
double bilinear(const Map& map, const Eigen::Vector2d& p)
{
  const Bilinear w = bilinearAt(map.origin(), map.pixel(), map.width(), map.height(), p);
  if (!w.on_map)
    return 0.0;
  return w.value(map.at(w.i0, w.j0), map.at(w.i1, w.j0), map.at(w.i0, w.j1), map.at(w.i1, w.j1));
}

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

/// \brief What a profile needs of the track besides the map: each laser-on sample's arc, spot and interior flag.
struct TrackGeometry
{
  std::vector<double> arc_m;
  std::vector<Eigen::Vector2d> where;  ///< the actual spot
  std::vector<char> interior;
};

TrackGeometry trackGeometry(const std::vector<SpotSample>& spots, double exclude_ends_m,
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
  TrackGeometry g;
  std::size_t on = 0;
  for (const SpotSample& s : spots)
  {
    on += s.power_w > 0.0 ? 1 : 0;
  }
  g.arc_m.reserve(on);
  g.where.reserve(on);
  g.interior.assign(on, 0);

  // Pass 1: arc and spot of every laser-on sample.
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
    g.arc_m.push_back(arc);
    g.where.push_back(s.actual);
  }

  // Pass 2: bursts (runs of laser-on samples consecutive in the stream), interior flags.
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
    const double arc_first = g.arc_m[first], arc_last = g.arc_m[last];
    for (std::size_t q = first; q <= last; ++q)
    {
      const double s = g.arc_m[q];
      g.interior[q] = track_ends ? !nearAnEnd(g.where[q], ends_by_x, exclude_ends_m)
                                 : (s - arc_first > exclude_ends_m && arc_last - s > exclude_ends_m);
    }
    m = last + 1;
    k = end;
  }
  return g;
}

/// \brief Mean, median, min and peak of the interior samples' E (\p values, at \p where, in stream order).
void addStatistics(TrackEnergyProfile& out, std::vector<double> values, const std::vector<Eigen::Vector2d>& where)
{
  double sum = 0.0;
  for (std::size_t q = 0; q < values.size(); ++q)
  {
    const double e = values[q];
    sum += e;
    if (q == 0 || e < out.min_jpm2)
      out.min_jpm2 = e;
    if (q == 0 || e > out.peak_jpm2)
    {
      out.peak_jpm2 = e;
      out.peak_point_m = where[q];
    }
  }
  const std::size_t n = values.size();
  out.interior_samples = n;
  if (n > 0)
  {
    out.mean_jpm2 = sum / static_cast<double>(n);
    const auto mid = values.begin() + static_cast<std::ptrdiff_t>(n / 2);
    std::nth_element(values.begin(), mid, values.end());
    double median = *mid;
    if (n % 2 == 0)
    {
      // The lower middle value is the largest of the part before mid.
      median = 0.5 * (median + *std::max_element(values.begin(), mid));
    }
    out.median_jpm2 = median;
  }
}
}  // namespace

TrackEnergyProfile trackEnergyProfile(const EnergyMap& map, const std::vector<SpotSample>& spots, double exclude_ends_m,
                                      const std::vector<Eigen::Vector2d>* track_ends)
{
  TrackGeometry g = trackGeometry(spots, exclude_ends_m, track_ends);
  TrackEnergyProfile out;
  out.energy_jpm2.reserve(g.where.size());
  std::vector<double> values;
  std::vector<Eigen::Vector2d> where;
  for (std::size_t q = 0; q < g.where.size(); ++q)
  {
    out.energy_jpm2.push_back(bilinear(map, g.where[q]));
    if (g.interior[q])
    {
      values.push_back(out.energy_jpm2.back());
      where.push_back(g.where[q]);
    }
  }
  addStatistics(out, std::move(values), where);
  out.arc_m = std::move(g.arc_m);
  out.interior = std::move(g.interior);
  return out;
}

TrackEnergySampler::TrackEnergySampler(const TiledEnergyMap& map, const std::vector<SpotSample>& spots,
                                       double exclude_ends_m, const std::vector<Eigen::Vector2d>* track_ends)
  : origin_(map.origin())
  , pixel_(map.pixel())
  , width_(map.width())
  , height_(map.height())
  , tiles_across_(map.tilesAcross())
{
  {
    const TrackGeometry g = trackGeometry(spots, exclude_ends_m, track_ends);
    for (std::size_t q = 0; q < g.where.size(); ++q)
      if (g.interior[q])
        where_.push_back(g.where[q]);
  }
  where_.shrink_to_fit();
  if (where_.size() > std::numeric_limits<std::uint32_t>::max())
    throw NumericalError("track energy: over 2^32 interior samples (lower energy.track_max_samples)");
  pixels_.assign(where_.size(), {0.0f, 0.0f, 0.0f, 0.0f});
  // One request per (tile, sample) the sample's four pixels lie on, sorted by tile: key = tile · 2^32 + sample.
  for (std::size_t q = 0; q < where_.size(); ++q)
  {
    const Bilinear w = bilinearAt(origin_, pixel_, width_, height_, where_[q]);
    if (!w.on_map)
      continue;
    const std::int64_t tiles[4] = {tileOf(w.i0, w.j0), tileOf(w.i1, w.j0), tileOf(w.i0, w.j1), tileOf(w.i1, w.j1)};
    for (int c = 0; c < 4; ++c)
      if (std::find(tiles, tiles + c, tiles[c]) == tiles + c)
        requests_.add(tiles[c], static_cast<std::uint32_t>(q));
  }
  requests_.sort();
}

std::int64_t TrackEnergySampler::tileOf(std::int64_t col, std::int64_t row) const
{
  return (row / TiledEnergyMap::kTileSide) * tiles_across_ + col / TiledEnergyMap::kTileSide;
}

void TrackEnergySampler::serve(std::int64_t tile, const float* data)
{
  constexpr std::int64_t side = TiledEnergyMap::kTileSide;
  requests_.forTile(tile, [&](std::uint32_t q) {
    const Bilinear w = bilinearAt(origin_, pixel_, width_, height_, where_[q]);
    const std::int64_t cols[4] = {w.i0, w.i1, w.i0, w.i1}, rows[4] = {w.j0, w.j0, w.j1, w.j1};
    for (int c = 0; c < 4; ++c)
      if (tileOf(cols[c], rows[c]) == tile)
        pixels_[q][static_cast<std::size_t>(c)] = data[(rows[c] % side) * side + cols[c] % side];
  });
}

TrackEnergyProfile TrackEnergySampler::finish(const TiledEnergyMap& map)
{
  // The tiles no pass served; untouched tiles read 0, as at(): their pixels stay 0.
  requests_.serveTheRest(map, [this](std::int64_t tile, const float* data) { serve(tile, data); });
  std::vector<double> values(where_.size());
  for (std::size_t q = 0; q < where_.size(); ++q)
  {
    const std::array<float, 4>& e = pixels_[q];
    values[q] = bilinearAt(origin_, pixel_, width_, height_, where_[q]).value(e[0], e[1], e[2], e[3]);
  }
  pixels_ = {};
  TrackEnergyProfile out;
  addStatistics(out, std::move(values), where_);
  return out;
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

DiscPeakSampler::DiscPeakSampler(const TiledEnergyMap& map, const std::vector<Eigen::Vector2d>& points,
                                 const std::vector<double>& radii_m)
  : tiles_across_(map.tilesAcross())
  , discs_(points.size())
  , peaks_(points.size(), 0.0)
{
  // Each disc as in peakNear: the pixel holding the point, and the pixels whose centre lies within r.
  const double p = map.pixel();
  const std::int64_t side = TiledEnergyMap::kTileSide;
  for (std::size_t i = 0; i < points.size(); ++i)
  {
    Disc& d = discs_[i];
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
        owed_.add(tr * tiles_across_ + tc, static_cast<std::uint32_t>(i));
  }
  owed_.sort();
}

void DiscPeakSampler::serve(std::int64_t tile, const float* data)
{
  const std::int64_t side = TiledEnergyMap::kTileSide;
  const std::int64_t tr = tile / tiles_across_, tc = tile % tiles_across_;
  owed_.forTile(tile, [&](std::uint32_t i) {
    const Disc& d = discs_[i];
    double& peak = peaks_[i];
    const std::int64_t r0 = std::max(d.row0, tr * side), r1 = std::min(d.row1, tr * side + side - 1);
    const std::int64_t c0 = std::max(d.col0, tc * side), c1 = std::min(d.col1, tc * side + side - 1);
    for (std::int64_t row = r0; row <= r1; ++row)
      for (std::int64_t col = c0; col <= c1; ++col)
      {
        const double dx = static_cast<double>(col) + 0.5 - d.u, dy = static_cast<double>(row) + 0.5 - d.v;
        if (dx * dx + dy * dy <= d.r * d.r || (col == d.point_col && row == d.point_row))
          peak = std::max(peak, static_cast<double>(data[(row - tr * side) * side + (col - tc * side)]));
      }
  });
}

std::vector<double> DiscPeakSampler::finish(const TiledEnergyMap& map)
{
  // The tiles no pass served; untouched tiles read 0 and E ≥ 0: they change no peak.
  owed_.serveTheRest(map, [this](std::int64_t tile, const float* data) { serve(tile, data); });
  return std::move(peaks_);
}
}  // namespace scanhead
