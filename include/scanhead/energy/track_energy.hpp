/// \file track_energy.hpp
/// \brief Deposited energy along the marked track: peaks at corners versus the straight-track
/// level (SPEC §5, NC §4: the corner test).
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "scanhead/common/chunk.hpp"
#include "scanhead/energy/energy_map.hpp"
#include "scanhead/energy/tile_requests.hpp"
#include "scanhead/energy/tiled_energy_map.hpp"

namespace scanhead
{
/// \brief E sampled at the actual spot centre of every laser-on sample, in stream order.
struct TrackEnergyProfile
{
  std::vector<double> arc_m;        ///< arc length of the actual spot path, laser-on samples only [m]
  std::vector<double> energy_jpm2;  ///< E at the spot centre, bilinear between pixel centres [J/m²]
  std::vector<char> interior;       ///< 1 if farther than exclude_ends_m from its burst's ends
  double mean_jpm2 = 0.0;           ///< mean over the interior samples [J/m²]
  double median_jpm2 = 0.0;         ///< median over the interior samples: the straight-track level [J/m²]
  double peak_jpm2 = 0.0;           ///< max over the interior samples [J/m²]
  double min_jpm2 = 0.0;            ///< min over the interior samples: the worst dip [J/m²]
  Eigen::Vector2d peak_point_m = Eigen::Vector2d::Zero();  ///< where the peak is [m]
  std::size_t interior_samples = 0;

  double peakToMean() const { return mean_jpm2 > 0.0 ? peak_jpm2 / mean_jpm2 : 0.0; }
  double peakToMedian() const { return median_jpm2 > 0.0 ? peak_jpm2 / median_jpm2 : 0.0; }
  double minToMedian() const { return median_jpm2 > 0.0 ? min_jpm2 / median_jpm2 : 0.0; }
};

/// \brief Samples \p map along \p spots (power > 0: laser on; a burst is a run of consecutive
/// laser-on samples). Samples within \p exclude_ends_m of arc length from either end of their
/// burst are not interior (the half-energy start and end of a track are not corners).
///
/// Interpolation (SPEC §5): with the pixel coordinates u = (x − origin.x)/pixel − 1/2,
/// v = (y − origin.y)/pixel − 1/2 (pixel centres at integer u, v), i = ⌊u⌋, j = ⌊v⌋, a = u − i, b = v − j,
/// \f[ E = (1-a)(1-b)\,E_{i,j} + a(1-b)\,E_{i+1,j} + (1-a)\,b\,E_{i,j+1} + a\,b\,E_{i+1,j+1}. \f]
/// Points off the map (outside [origin, origin + (width, height)·pixel]) read 0; in the half-pixel
/// band between the outer pixel centres and the map edge, u and v are clamped to the outer centres
/// (the edge pixels' values are extended, not faded to 0).
///
/// Arc length: arc_m grows by |actual_k − actual_{k−1}| between consecutive laser-on samples of a
/// burst; it does not grow across the laser-off gap between bursts (so it is continuous, and the
/// arc of a burst is its last arc_m minus its first). A sample is interior if
/// arc − arc_first > exclude_ends_m and arc_last − arc > exclude_ends_m (strictly).
/// With \p track_ends, a sample is interior if its spot is farther than exclude_ends_m from every
/// point of track_ends instead (the marks' first and last points: a burst that skywriting or a
/// delay cut at a corner does not hide the corner).
/// The median of an even count is the mean of the two middle values. With no interior sample,
/// mean, median, peak and interior_samples are 0.
/// \param[in] exclude_ends_m >= 0 [m]
/// \param[in] track_ends     optional: where the marked tracks start and end [m]
/// \throws ConfigError if exclude_ends_m is not finite and >= 0
/// \throws NumericalError on a non-finite actual spot of a laser-on sample
TrackEnergyProfile trackEnergyProfile(const EnergyMap& map, const std::vector<SpotSample>& spots, double exclude_ends_m,
                                      const std::vector<Eigen::Vector2d>* track_ends = nullptr);

/// \brief trackEnergyProfile() on the sparse map of a run, from the tiles a pass over the map reads anyway
/// (TiledEnergyMap::regions: the results' overview reads every tile once, so the spill file is read once for both).
///
/// The constructor takes what it needs of the track (the interior samples' spots: 16 B each; the samples may be freed
/// then); serve() takes each tile's pixels the sample's four pixels lie on; finish() reads the tiles no pass served and
/// returns the statistics, bit for bit those of trackEnergyProfile on the same pixels (the same bilinear expression on
/// the same floats, the same order). The per-sample arrays (arc_m, energy_jpm2, interior) are left empty: a layer's
/// million samples are not kept.
class TrackEnergySampler
{
public:
  /// \throws ConfigError, NumericalError as trackEnergyProfile
  TrackEnergySampler(const TiledEnergyMap& map, const std::vector<SpotSample>& spots, double exclude_ends_m,
                     const std::vector<Eigen::Vector2d>* track_ends = nullptr);
  /// \brief Tile \p tile's pixels (kTileSide², row-major), read by a pass; a tile may come twice.
  void serve(std::int64_t tile, const float* data);
  /// \brief The profile's statistics (the tiles not served are read from \p map now). The last call.
  TrackEnergyProfile finish(const TiledEnergyMap& map);

private:
  std::int64_t tileOf(std::int64_t col, std::int64_t row) const;

  Eigen::Vector2d origin_;  ///< the map's geometry, for the bilinear weights
  double pixel_ = 0.0;
  std::int64_t width_ = 0, height_ = 0, tiles_across_ = 0;
  std::vector<Eigen::Vector2d> where_;        ///< the interior samples' spots, in stream order
  std::vector<std::array<float, 4>> pixels_;  ///< their four pixels (i0, j0), (i1, j0), (i0, j1), (i1, j1)
  TileRequests requests_;                     ///< the tiles each sample's pixels lie on
};

/// \brief Largest E [J/m²] over the pixels whose centre lies within \p radius_m of \p point
/// (the pixel holding the point if none does); 0 off the map.
double peakNear(const TiledEnergyMap& map, const Eigen::Vector2d& point, double radius_m);

/// \brief peakNear() of many discs from the tiles a pass over the map reads anyway (as TrackEnergySampler): each
/// tile served serves every disc that overlaps it; finish() reads the tiles still owed. A maximum does not depend on
/// the order in which its pixels are seen (E ≥ 0; untouched pixels read 0): the values of peakNear, bit for bit, with
/// no read of the spill file of its own (the THESIS layer's corner peaks: 4.2 s of reads).
class DiscPeakSampler
{
public:
  /// \param[in] radii_m one per point [m]
  DiscPeakSampler(const TiledEnergyMap& map, const std::vector<Eigen::Vector2d>& points,
                  const std::vector<double>& radii_m);
  /// \brief Tile \p tile's pixels (kTileSide², row-major), read by a pass; a tile may come twice.
  void serve(std::int64_t tile, const float* data);
  /// \brief Each disc's peak (the tiles not served are read from \p map now). The last call.
  std::vector<double> finish(const TiledEnergyMap& map);

private:
  struct Disc
  {
    double u = 0.0, v = 0.0, r = 0.0;  ///< centre and radius [pixels]
    std::int64_t col0 = 0, col1 = 0, row0 = 0, row1 = 0, point_col = 0, point_row = 0;
  };
  std::int64_t tiles_across_ = 0;
  std::vector<Disc> discs_;
  std::vector<double> peaks_;
  TileRequests owed_;  ///< the tiles each disc overlaps
};
}  // namespace scanhead
