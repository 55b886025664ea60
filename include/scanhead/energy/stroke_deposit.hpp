/// \file stroke_deposit.hpp
/// \brief A stroke's energy drawn on the map by the closed form of segment_integral.hpp (energy.method: exact).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "scanhead/energy/energy_config.hpp"
#include "scanhead/energy/stroke_merger.hpp"
#include "scanhead/energy/tiled_energy_map.hpp"

namespace scanhead
{
/// \brief A stroke's pixel weights, computed apart from the map (StrokeDeposit::weigh) so that several threads can
/// weigh strokes while one adds them to the map in stream order (StrokeDeposit::apply): the same floats either way.
struct StrokeWeights
{
  struct Row
  {
    std::int64_t row = 0, col = 0;  ///< map row, first map column
    int n = 0;                      ///< pixels
    std::size_t offset = 0;         ///< into weights
    double sum = 0.0;               ///< Σ of its float weights
  };
  std::vector<float> weights;
  std::vector<Row> rows;
  double total = 0.0;     ///< Σ of the rows' sums, in row order
  double energy_j = 0.0;  ///< the stroke's energy
  Eigen::Vector2d midpoint = Eigen::Vector2d::Zero();
  bool off_map = false;  ///< the whole capsule lies off the map
};

/// \brief Draws one Stroke: the weights W(r) of SegmentIntegral at the pixel centres of the capsule of radius
/// R = truncation_radii·w_major around the segment start → start + n·Δ (the footprint truncated as the sampled
/// method truncates each sub-step: across the stroke and beyond both ends), scaled so that they sum to exactly the
/// stroke's energy / pixel² (the share on pixels off the map goes to the caller's outside energy).
///
/// Two evaluations, 8 columns at a time in float lanes (src/energy/lane_math.hpp: exp by Cephes' expf, relative error
/// ≤ 2 ulp; erf by Abramowitz & Stegun 7.1.28, |error| ≤ 4e-6 in float; AVX2 and default clones give the same bits):
/// - √A ≤ 6 (strokes up to ~150 µm at w = 35 µm: on two THESIS squares 95 % of the strokes and 84 % of the pixels): the
///   bracket erf(√A − u) + erf(u) by Gauss–Legendre quadrature in τ with 4–14 nodes (src/energy/gauss_legendre.hpp,
///   |error| ≤ 9.5e-7), over the rectangle of pixels that bounds the capsule: every row has the same columns, so the
///   Gaussian's first block and the nodes' factors follow from the previous row's by products (anchored every 8 rows)
///   and a row costs no exponential and no chord; pixels outside the capsule weigh 0 and are trimmed from the rows;
/// - longer strokes row by row over the capsule (a disc at each end, a band between, each row's column range found
///   analytically): the cross factor exp(−(mᵀr)²) everywhere, the bracket by erf only outside the run where |u| and
///   |√A − u| exceed 6 (there it is 2 to float precision); stationary ones as the dwell's Gaussian.
/// The Gaussians are quadratic exponents along a row: two exponentials every 8 blocks and two products a block between
/// (GaussianSteps in the .cpp). Every exponent is formed in double and rounded once (the quadrature's anchors split
/// into float hi + lo), so the weights keep float precision (~1e-6 of the peak, far inside the 2e-3 budget of issue
/// 13: test_stroke_deposit.cpp measures 3.7e-6 against the closed form in double, the truncation's renormalisation
/// included). Rows are stored as floats, summed in a fixed order, then added with TiledEnergyMap::addRow (one tile
/// lookup per row span). Cost: ~(2R/p)·(L/p + 2R/p) pixel weights per stroke of length L (a long stroke: 2R/p = 35 new
/// pixels per pixel of length at 5 µm), ~2 ns each with the map's add on AVX2 (a row's fixed cost included).
class StrokeDeposit
{
public:
  explicit StrokeDeposit(const EnergyConfig& config);
  /// \brief The weights of \p stroke on \p map's grid into \p out. Reads only the map's geometry (origin, pixel, size)
  /// and changes nothing here: any number of threads may weigh at once, each into its own \p out.
  void weigh(const TiledEnergyMap& map, const Stroke& stroke, StrokeWeights& out) const;
  /// \brief Adds weights of weigh() (same map) to \p map; the energy drawn off the map goes to \p outside_j [J].
  void apply(TiledEnergyMap& map, const StrokeWeights& weights, double& outside_j);
  std::uint64_t pixelsDrawn() const { return pixels_; }  ///< pixel weights computed so far (cost measure)
  void resetCounters() { pixels_ = 0; }

private:
  EnergyConfig config_;
  std::uint64_t pixels_ = 0;
};
}  // namespace scanhead
