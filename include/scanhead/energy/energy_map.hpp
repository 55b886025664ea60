/// \file energy_map.hpp
/// \brief Deposited energy density on a pixel grid of the work plane, and its accumulation.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "scanhead/common/chunk.hpp"
#include "scanhead/energy/energy_config.hpp"

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

/// \brief y[k] += c·x[k], k < n: the hot loop of the accumulator (one stencil row), vectorised with
/// GCC/Clang vector extensions; the order of operations per element is fixed (bit-reproducible).
void axpyRow(float* y, const float* x, float c, int n);

/// \brief Pixels across an extent: max(1, ⌈extent/pixel⌉) with a 1e-9 pixel tolerance (a 100 µm box
/// at 1 µm is 100 pixels, not 101 by rounding), for dense and tiled maps alike.
double pixelsAcross(double extent_m, double pixel_m);

/// \brief The checks of a map's geometry, dense or tiled.
/// \throws ConfigError if pixel_m is not finite and > 0 (names energy.pixel_m)
/// \throws InputError if the corners are not finite or max < min
void checkMapGeometry(const Eigen::Vector2d& min_corner, const Eigen::Vector2d& max_corner, double pixel_m);

}  // namespace scanhead
