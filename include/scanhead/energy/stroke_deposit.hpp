/// \file stroke_deposit.hpp
/// \brief A stroke's energy drawn on the map by the closed form of segment_integral.hpp (energy.method: exact).
#pragma once

#include <cstdint>
#include <vector>

#include "scanhead/energy/energy_config.hpp"
#include "scanhead/energy/stroke_merger.hpp"
#include "scanhead/energy/tiled_energy_map.hpp"

namespace scanhead
{
/// \brief Draws one Stroke: the weights W(r) of SegmentIntegral at the pixel centres of the capsule of radius
/// R = truncation_radii·w_major around the segment start → start + n·Δ (the footprint truncated as the sampled
/// method truncates each sub-step: across the stroke and beyond both ends), scaled so that they sum to exactly the
/// stroke's energy / pixel² (the share on pixels off the map goes to the caller's outside energy).
///
/// Row by row: the capsule's column range follows analytically (a disc at each end, a band between); along a row
/// the cross factor exp(−(mᵀr)²) (a stationary stroke: exp(−q_xx(x − x*)²)) follows the multiplicative recurrence of
/// gaussianWeights (no exponential per pixel), and the bracket erf(√A − u) + erf(u) is evaluated only where
/// |u| < 6 or |√A − u| < 6: elsewhere it is exactly 2 (along the stroke) or 0 (beyond its ends) in double. Rows are
/// stored as floats, summed in a fixed order, then added with TiledEnergyMap::addRow. Cost: ~(2R/p)·(L/p + 2R/p)
/// pixel weights per stroke of length L (a long stroke: 2R/p = 35 new pixels per pixel of length at 5 µm).
class StrokeDeposit
{
public:
  explicit StrokeDeposit(const EnergyConfig& config);
  /// \brief Deposits \p stroke on \p map; adds the energy drawn off the map to \p outside_j [J].
  void deposit(TiledEnergyMap& map, const Stroke& stroke, double& outside_j);
  std::uint64_t pixelsDrawn() const { return pixels_; }  ///< pixel weights computed so far (cost measure)
  void resetCounters() { pixels_ = 0; }

private:
  struct Row
  {
    std::int64_t row = 0, col = 0;  ///< map row, first map column
    int n = 0;                      ///< pixels
    std::size_t offset = 0;         ///< into weights_
    double sum = 0.0;               ///< Σ of its float weights
  };
  EnergyConfig config_;
  std::vector<float> weights_;
  std::vector<double> cross_;
  std::vector<Row> rows_;
  std::uint64_t pixels_ = 0;
};
}  // namespace scanhead
