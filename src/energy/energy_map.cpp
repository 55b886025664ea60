/// \file energy_map.cpp
/// \brief Dense energy map (images, regions) and the stencil row kernel.
#include "scanhead/energy/energy_map.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <sstream>

#include "scanhead/common/errors.hpp"

namespace scanhead
{
namespace
{
constexpr double kMaxPixels = 2147483648.0;  // 2^31

}  // namespace

namespace
{
/// \brief y[k] += c·x[k] in vectors of \p Vec (GCC/Clang vector extensions: vectorised at -O2 on any target), then
/// one at a time; each element's operations are the same whatever the vector width, so the results are too.
template <class Vec>
inline void axpyVectors(float* y, const float* x, float c, int n)
{
  constexpr int lanes = sizeof(Vec) / sizeof(float);
  Vec cv = {};
  cv += c;
  int k = 0;
  for (; k + lanes <= n; k += lanes)
  {
    Vec xv, yv;
    std::memcpy(&xv, x + k, sizeof(Vec));
    std::memcpy(&yv, y + k, sizeof(Vec));
    yv += cv * xv;
    std::memcpy(y + k, &yv, sizeof(Vec));
  }
  for (; k < n; ++k)
  {
    y[k] += c * x[k];
  }
}
typedef float Float4 __attribute__((vector_size(16)));
typedef float Float8 __attribute__((vector_size(32)));

#if defined(__GNUC__) && defined(__x86_64__)
/// AVX2's 32-byte vectors where the CPU has them (the library is built for baseline x86-64: SSE2, where 32-byte vectors
/// are split and spilled); no FMA either way (-ffp-contract=off), so the same bits.
__attribute__((target("avx2"))) void axpyRowAvx2(float* y, const float* x, float c, int n)
{
  axpyVectors<Float8>(y, x, c, n);
}
const bool kHasAvx2 = __builtin_cpu_supports("avx2");
#endif
}  // namespace

/// \brief y[k] += c·x[k], k < n: the hot loop of the accumulator (one map row of a window's weights).
///
/// The order of operations per element is fixed, so results depend only on the inputs (chunk invariance holds bit for
/// bit) and not on the vector width.
void axpyRow(float* y, const float* x, float c, int n)
{
#if defined(__GNUC__) && defined(__x86_64__)
  if (kHasAvx2)
  {
    axpyRowAvx2(y, x, c, n);
    return;
  }
#endif
  axpyVectors<Float4>(y, x, c, n);  // 16-byte vectors: native on SSE2 / NEON
}

double pixelsAcross(double extent_m, double pixel_m)
{
  return std::max(1.0, std::ceil(extent_m / pixel_m - 1e-9));
}

void checkMapGeometry(const Eigen::Vector2d& min_corner, const Eigen::Vector2d& max_corner, double pixel_m)
{
  if (!(pixel_m > 0.0) || !std::isfinite(pixel_m))
  {
    std::ostringstream msg;
    msg << "energy.pixel_m must be > 0 (got " << pixel_m << ")";
    throw ConfigError(msg.str());
  }
  if (!min_corner.allFinite() || !max_corner.allFinite() || (max_corner.array() < min_corner.array()).any())
  {
    std::ostringstream msg;
    msg << "energy map bounds must be finite with max >= min (got min (" << min_corner.x() << ", " << min_corner.y()
        << ") m, max (" << max_corner.x() << ", " << max_corner.y() << ") m)";
    throw InputError(msg.str());
  }
}

// ---------------------------------------------------------------------------------------------
// EnergyMap

EnergyMap::EnergyMap(const Eigen::Vector2d& min_corner, const Eigen::Vector2d& max_corner, double pixel_m)
  : origin_(min_corner)
  , pixel_(pixel_m)
  , width_(0)
  , height_(0)
{
  checkMapGeometry(min_corner, max_corner, pixel_m);
  const double w = pixelsAcross(max_corner.x() - min_corner.x(), pixel_m);
  const double h = pixelsAcross(max_corner.y() - min_corner.y(), pixel_m);
  if (w * h > kMaxPixels)
  {
    std::ostringstream msg;
    msg << "energy.pixel_m = " << pixel_m << " m gives a " << w << " x " << h << " pixel map (" << w * h
        << " pixels, limit 2^31 = " << kMaxPixels
        << "): increase energy.pixel_m or reduce energy.map_margin_m / the job extent";
    throw ConfigError(msg.str());
  }
  width_ = static_cast<int>(w);
  height_ = static_cast<int>(h);
  data_.assign(static_cast<std::size_t>(width_) * static_cast<std::size_t>(height_), 0.0f);
}

double EnergyMap::totalEnergy() const
{
  // Eight partial sums in a fixed order: deterministic, and the adds overlap instead of waiting
  // on one long dependency chain (a whole map is summed after every job).
  constexpr std::size_t kLanes = 8;
  double lanes[kLanes] = {};
  const std::size_t n = data_.size();
  const std::size_t whole = n - n % kLanes;
  for (std::size_t i = 0; i < whole; i += kLanes)
  {
    for (std::size_t k = 0; k < kLanes; ++k)
    {
      lanes[k] += data_[i + k];
    }
  }
  double sum = 0.0;
  for (const double lane : lanes)
  {
    sum += lane;
  }
  for (std::size_t i = whole; i < n; ++i)
  {
    sum += data_[i];
  }
  return sum * pixel_ * pixel_;
}

double EnergyMap::peak() const
{
  constexpr std::size_t kLanes = 8;  // as in totalEnergy(): independent maxima, then combined
  float lanes[kLanes] = {};
  const std::size_t n = data_.size();
  const std::size_t whole = n - n % kLanes;
  for (std::size_t i = 0; i < whole; i += kLanes)
  {
    for (std::size_t k = 0; k < kLanes; ++k)
    {
      lanes[k] = data_[i + k] > lanes[k] ? data_[i + k] : lanes[k];
    }
  }
  float m = 0.0f;
  for (const float lane : lanes)
  {
    m = std::max(m, lane);
  }
  for (std::size_t i = whole; i < n; ++i)
  {
    m = std::max(m, data_[i]);
  }
  return m;
}

void EnergyMap::clear()
{
  std::fill(data_.begin(), data_.end(), 0.0f);
}

}  // namespace scanhead
