/// \file energy_map.hpp
/// \brief Deposited energy density on a pixel grid of the work plane, and its accumulation.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "scanhead/core/chunk.hpp"
#include "scanhead/core/energy_config.hpp"

namespace scanhead
{
/// \brief Energy density E [J/m²] at pixel centres origin + (i + 0.5, j + 0.5)·pixel.
///
/// Row-major float storage: row j (y) holds columns i (x); row 0 is at the lowest y.
class EnergyMap
{
public:
  /// \brief A map covering [min_corner, max_corner]: width = max(1, ceil((max.x − min.x)/pixel)), same in y.
  /// \throws ConfigError if pixel_m is not > 0 or the map would exceed 2^31 pixels (names energy.pixel_m)
  /// \throws InputError if the corners are not finite or max < min
  EnergyMap(const Eigen::Vector2d& min_corner, const Eigen::Vector2d& max_corner, double pixel_m);
  int width() const { return width_; }
  int height() const { return height_; }
  double pixel() const { return pixel_; }
  const Eigen::Vector2d& origin() const { return origin_; }
  float at(int col, int row) const { return data_[static_cast<std::size_t>(row) * width_ + col]; }
  float* row(int r) { return data_.data() + static_cast<std::size_t>(r) * width_; }
  const std::vector<float>& data() const { return data_; }
  double totalEnergy() const;  ///< Σ E·pixel² [J] (summed in double)
  double peak() const;         ///< max E [J/m²]
  void clear();

private:
  Eigen::Vector2d origin_;
  double pixel_;
  int width_, height_;
  std::vector<float> data_;
};

/// \brief Integrates the Gaussian spot I(r) = 2P/(πw²)·exp(-2r²/w²) along the spot stream (SPEC §5).
///
/// The energy of sample k, P_k·Ts, is spread evenly over m sub-steps at the midpoints of m equal
/// parts of the segment from the actual spot k to k+1,
/// \f[ m = \max\left(1, \left\lceil \frac{|x_{k+1} - x_k|}{\mathrm{max\_substep\_radii}\cdot w} \right\rceil\right), \f]
/// so a fast spot leaves no ripple; each sub-step adds
/// \f[ E(p) \mathrel{+}= \frac{P_k T_s}{m}\,\frac{2}{\pi w^2}\,e^{-2|p - c|^2/w^2} \f]
/// point-sampled at the pixel centres of a stencil: the disc of radius truncation_radii·w + 0.71·pixel
/// around the pixel holding c (so it holds every pixel within truncation_radii·w of c), its rows widened
/// on the right to whole groups of 4 pixels (for the vector loop), then scaled so the stencil's
/// weights sum to exactly (P_k T_s/m)/pixel² (energy conserved to rounding whatever the pixel; the
/// part on pixels off the map is added to energyOutsideMap()).
/// The last sample stays pending until the next one arrives (so chunking does not change the
/// result, bit for bit); finish() deposits it as a stationary dwell.
///
/// Stream anomalies: samples whose global index was already seen (overlap, late chunk) are
/// skipped; at a gap the pending sample is deposited as a dwell (its successor is unknown).
/// Samples with zero power deposit nothing. The spot is circular (oblique-incidence stretch is
/// not modelled).
class EnergyAccumulator
{
public:
  /// \throws ConfigError from config.validate() or the map size check
  EnergyAccumulator(const EnergyConfig& config, const Eigen::Vector2d& min_corner, const Eigen::Vector2d& max_corner);
  void reset();
  /// \throws NumericalError on a non-finite position of a sample that carries power
  void process(const SpotChunk& chunk);
  /// \brief Deposits the last pending sample (call once at the end of the stream).
  void finish();
  const EnergyMap& map() const { return map_; }
  double energyOutsideMap() const { return outside_j_; }  ///< footprint energy that fell off the map [J]

private:
  void deposit(const Eigen::Vector2d& from, const Eigen::Vector2d& to, double energy_j);
  void depositPoint(double cx, double cy, double energy_j);
  EnergyConfig config_;
  EnergyMap map_;
  bool has_pending_ = false;
  SpotSample pending_;
  double period_s_ = 0.0;        ///< period of the chunk that delivered the pending sample [s]
  bool started_ = false;         ///< a sample has been seen since construction / reset()
  std::uint64_t next_index_ = 0; ///< global index expected next
  double outside_j_ = 0.0;

  // Footprint geometry, fixed at construction.
  double w_m_ = 0.0;              ///< 1/e² radius [m]
  double a_ = 0.0;                ///< 2/w² [1/m²]
  double q_ = 0.0;                ///< exp(-2·a·pixel²), ratio step of the Gaussian recurrence
  double substep_m_ = 0.0;        ///< longest sub-step [m]
  int half_ = 0;                  ///< stencil half size H [pixels]
  std::vector<int> row_lo_, row_hi_;  ///< stencil row t: local columns [row_lo_, row_hi_] (centre column H)
  // Scratch (no allocation per sample).
  std::vector<double> gx_, gy_, prefix_x_;
  std::vector<float> gxf_;
};
}  // namespace scanhead
