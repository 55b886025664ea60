/// \file energy_accumulator.hpp
/// \brief Integrates the spot's irradiance along the spot stream into the sparse energy map (SPEC §5).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "scanhead/common/chunk.hpp"
#include "scanhead/common/chunk_sequencer.hpp"
#include "scanhead/energy/energy_config.hpp"
#include "scanhead/energy/spot_footprint.hpp"
#include "scanhead/energy/tiled_energy_map.hpp"

namespace scanhead
{
/// \brief E(p) = ∫ I(p − x_exp(t), t) dt on a TiledEnergyMap, I the footprint of spot_footprint.hpp.
///
/// The energy of sample k, P_k·Ts, is spread evenly over m sub-steps at the midpoints of m equal
/// parts of the segment from the actual spot k to k+1,
/// \f[ m = \max\left(1, \left\lceil \frac{|x_{k+1} - x_k|}{\mathrm{max\_substep\_radii}\cdot w} \right\rceil\right),
/// \f] (w the footprint's smaller radius), so a fast spot leaves no ripple; each sub-step adds \f[ E(p) \mathrel{+}=
/// \frac{P_k T_s}{m}\,\frac{\sqrt{\det Q}}{\pi}\,e^{-(p - c)^\top Q (p - c)} \f] point-sampled at the pixel centres of
/// a stencil: the disc of radius truncation_radii·w_major + 0.71·pixel around the pixel holding c, its rows widened on
/// the right to whole groups of 4 pixels (for the vector loop), then scaled so the stencil's weights sum to exactly
/// (P_k T_s/m)/pixel² (energy conserved to rounding whatever the pixel, the incidence and the defocus; the part on
/// pixels off the map is added to energyOutsideMap()). The weights factor as rows × columns × a power table E_k^t (E_k
/// = exp(−2 q_xy p x_k)) updated row by row, so no exponential is taken per row; for the circular spot (q_xy = 0) they
/// are separable. The footprint follows the beam direction of the sample that carries the energy. The last sample stays
/// pending until the next one arrives (so chunking does not change the result, bit for bit); finish() deposits it as a
/// stationary dwell.
///
/// Stream anomalies: samples whose global index was already seen (overlap, late chunk) are
/// skipped; at a gap the pending sample is deposited as a dwell (its successor is unknown).
/// Samples with zero power deposit nothing.
class EnergyAccumulator
{
public:
  /// \throws ConfigError from config.validate() or the map size check
  EnergyAccumulator(const EnergyConfig& config, const Eigen::Vector2d& min_corner, const Eigen::Vector2d& max_corner);
  void reset();
  /// \throws NumericalError on a non-finite position or direction of a sample that carries power
  void process(const SpotChunk& chunk);
  /// \brief Deposits the last pending sample (call once at the end of the stream).
  void finish();
  const TiledEnergyMap& map() const { return map_; }
  double energyOutsideMap() const { return outside_j_; }  ///< footprint energy that fell off the map [J]

private:
  void deposit(const SpotSample& from, const Eigen::Vector2d& to, double energy_j);
  void depositPoint(double cx, double cy, double energy_j, const SpotFootprint& fp);
  EnergyConfig config_;
  TiledEnergyMap map_;
  bool has_pending_ = false;
  SpotSample pending_;
  double period_s_ = 0.0;    ///< period of the chunk that delivered the pending sample [s]
  ChunkSequencer sequence_;  ///< which samples are new, where the stream broke
  double outside_j_ = 0.0;
  // Scratch (no allocation per sample).
  std::vector<double> gx_, gy_, row_sum_, prefix_;
  std::vector<float> gxf_, power_, ratio_;
  double span_radius_ = -1.0;           ///< stencil radius [pixels] the row spans below are for
  std::vector<int> span_lo_, span_hi_;  ///< stencil row t: local columns [lo, hi]
};
}  // namespace scanhead
