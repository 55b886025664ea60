/// \file sampled_deposit.hpp
/// \brief The spot's energy point-sampled at sub-steps along the path (energy.method: sampled; SPEC §5).
#pragma once

#include <Eigen/Core>
#include <vector>

#include "scanhead/common/chunk.hpp"
#include "scanhead/energy/energy_config.hpp"
#include "scanhead/energy/spot_footprint.hpp"
#include "scanhead/energy/tiled_energy_map.hpp"

namespace scanhead
{
/// \brief Deposits one sample's energy by point-sampling its footprint along the segment it sweeps.
///
/// The energy of sample k, P_k·Ts, is spread evenly over m sub-steps at the midpoints of m equal
/// parts of the segment from the actual spot k to k+1,
/// \f[ m = \max\left(1, \left\lceil \frac{|x_{k+1} - x_k|}{\mathrm{max\_substep\_radii}\cdot w} \right\rceil\right),
/// \f] (w the footprint's smaller radius), so a fast spot leaves no ripple; each sub-step adds \f[ E(p) \mathrel{+}=
/// \frac{P_k T_s}{m}\,\frac{\sqrt{\det Q}}{\pi}\,e^{-(p - c)^\top Q (p - c)} \f] point-sampled at the pixel centres of
/// a stencil: the disc of radius truncation_radii·w_major + 0.71·pixel around the pixel holding c, its rows widened on
/// the right to whole groups of 4 pixels (for the vector loop), then scaled so the stencil's weights sum to exactly
/// (P_k T_s/m)/pixel² (energy conserved to rounding whatever the pixel, the incidence and the defocus; the part on
/// pixels off the map is added to the caller's outside energy). The weights factor as rows × columns × a power table
/// E_k^t (E_k = exp(−2 q_xy p x_k)) updated row by row, so no exponential is taken per row; for the circular spot
/// (q_xy = 0) they are separable. Cost: ~π·(2.5 w/p)² ≈ 1,000 pixel updates per sub-step at 5 µm pixels.
/// Kept as the reference of the exact method (stroke_deposit.hpp) and for tests.
class SampledDeposit
{
public:
  explicit SampledDeposit(const EnergyConfig& config);
  /// \brief Deposits \p energy_j swept by the footprint of \p from (its actual position and beam direction) to \p to.
  /// \param[in,out] outside_j energy of stencil pixels off the map, added to [J]
  /// \throws NumericalError on a non-finite position or direction, or an implausibly long move
  /// \throws ConfigError if the footprint's stencil exceeds 1e4 pixels
  void deposit(TiledEnergyMap& map, const SpotSample& from, const Eigen::Vector2d& to, double energy_j,
               double& outside_j);

private:
  void depositPoint(TiledEnergyMap& map, double cx, double cy, double energy_j, const SpotFootprint& fp,
                    double& outside_j);
  EnergyConfig config_;
  SpotFootprintModel footprint_;  ///< the footprint of a sample's beam direction
  // Scratch (no allocation per sample).
  std::vector<double> gx_, gy_, row_sum_, prefix_;
  std::vector<float> gxf_, power_, ratio_;
  double span_radius_ = -1.0;           ///< stencil radius [pixels] the row spans below are for
  std::vector<int> span_lo_, span_hi_;  ///< stencil row t: local columns [lo, hi]
};
}  // namespace scanhead
