/// \file energy_map.cpp
/// \brief Energy map storage and the Gaussian-spot accumulator (SPEC §5).
#include "scanhead/core/energy_map.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <sstream>

#include "scanhead/core/errors.hpp"

namespace scanhead
{
namespace
{
constexpr double kMaxPixels = 2147483648.0;  // 2^31
constexpr double kMaxSubsteps = 1.0e8;       // a longer segment is garbage, not a path

/// \brief y[k] += c·x[k], k < n: the hot loop of the accumulator (one stencil row).
///
/// Written with GCC/Clang vector extensions so it is vectorised at -O2 on any target
/// (SSE on x86-64, NEON on ARM); the order of operations per element is fixed, so results
/// depend only on the inputs (chunk invariance holds bit for bit).
inline void axpyRow(float* y, const float* x, float c, int n)
{
  int k = 0;
#if defined(__GNUC__)
#if defined(__AVX__)
  typedef float Vec8 __attribute__((vector_size(32)));
  const Vec8 cv8 = { c, c, c, c, c, c, c, c };
  for (; k + 8 <= n; k += 8)
  {
    Vec8 xv, yv;
    std::memcpy(&xv, x + k, sizeof(Vec8));
    std::memcpy(&yv, y + k, sizeof(Vec8));
    yv += cv8 * xv;
    std::memcpy(y + k, &yv, sizeof(Vec8));
  }
#endif
  // 16-byte vectors: native on SSE2 / NEON (32-byte ones are split and spilled without AVX).
  typedef float Vec4 __attribute__((vector_size(16)));
  const Vec4 cv = { c, c, c, c };
  for (; k + 4 <= n; k += 4)
  {
    Vec4 xv, yv;
    std::memcpy(&xv, x + k, sizeof(Vec4));
    std::memcpy(&yv, y + k, sizeof(Vec4));
    yv += cv * xv;
    std::memcpy(y + k, &yv, sizeof(Vec4));
  }
#endif
  for (; k < n; ++k)
  {
    y[k] += c * x[k];
  }
}

/// \brief 1-D Gaussian weights g[k] = exp(-a·d_k²), d_k = d_centre + (k − H)·p, k = 0..n−1 (n > H).
///
/// Recurrence from the centre outwards (3 exps instead of 2H+1): with r_k = exp(-a(2 d_k p + p²)),
/// g_{k+1} = g_k·r_k and r_{k+1} = r_k·q, q = exp(-2 a p²); mirrored to the left. Starting at the
/// centre (|d| ≤ p/2, g ≈ 1) keeps the relative error ~H·1e-16 and lets far weights underflow to 0
/// harmlessly.
void gaussianWeights(double d_centre, double a, double p, double q, int half, int n, double* g)
{
  g[half] = std::exp(-a * d_centre * d_centre);
  double r = std::exp(-a * (2.0 * d_centre * p + p * p));
  for (int k = half; k + 1 < n; ++k)
  {
    g[k + 1] = g[k] * r;
    r *= q;
  }
  double l = std::exp(-a * (-2.0 * d_centre * p + p * p));
  for (int k = half; k > 0; --k)
  {
    g[k - 1] = g[k] * l;
    l *= q;
  }
}
}  // namespace

// ---------------------------------------------------------------------------------------------
// EnergyMap

EnergyMap::EnergyMap(const Eigen::Vector2d& min_corner, const Eigen::Vector2d& max_corner, double pixel_m)
  : origin_(min_corner), pixel_(pixel_m), width_(0), height_(0)
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
    msg << "energy map bounds must be finite with max >= min (got min (" << min_corner.x() << ", "
        << min_corner.y() << ") m, max (" << max_corner.x() << ", " << max_corner.y() << ") m)";
    throw InputError(msg.str());
  }
  // ceil with a 1e-9 pixel tolerance: a 100 µm box at 1 µm is 100 pixels, not 101 by rounding.
  const double w = std::max(1.0, std::ceil((max_corner.x() - min_corner.x()) / pixel_m - 1e-9));
  const double h = std::max(1.0, std::ceil((max_corner.y() - min_corner.y()) / pixel_m - 1e-9));
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

// ---------------------------------------------------------------------------------------------
// EnergyAccumulator

namespace
{
const EnergyConfig& validated(const EnergyConfig& config)
{
  config.validate();
  return config;
}
}  // namespace

EnergyAccumulator::EnergyAccumulator(const EnergyConfig& config, const Eigen::Vector2d& min_corner,
                                     const Eigen::Vector2d& max_corner)
  : config_(validated(config)), map_(min_corner, max_corner, config.pixel_m)
{
  const double p = config_.pixel_m;
  w_m_ = 0.5 * config_.spot_diameter_m;
  a_ = 2.0 / (w_m_ * w_m_);
  q_ = std::exp(-2.0 * a_ * p * p);
  substep_m_ = config_.max_substep_radii * w_m_;
  // Stencil radius in pixels: every pixel centre within R = truncation_radii·w of a point of the
  // centre pixel lies within R/p + sqrt(1/2) of the centre pixel's centre.
  const double rs = config_.truncation_radii * w_m_ / p + std::sqrt(0.5);
  if (rs > 1.0e5)
  {
    std::ostringstream msg;
    msg << "energy.pixel_m = " << p << " m is too fine for the spot (stencil radius " << rs << " pixels)";
    throw ConfigError(msg.str());
  }
  half_ = static_cast<int>(std::floor(rs));
  // Row t (offset dj = t − H) covers the columns within rs of the centre, |di| ≤ floor(sqrt(rs² − dj²)),
  // widened on the right to a multiple of 4 columns so the row loop has no scalar tail (the stencil
  // is any set of pixels containing the disc: the normalisation makes it conserve energy exactly).
  const int rows = 2 * half_ + 1;
  const int cols = (rows + 3 + 3) / 4 * 4;  // room for the widened rows, a multiple of 4
  row_lo_.resize(static_cast<std::size_t>(rows));
  row_hi_.resize(static_cast<std::size_t>(rows));
  for (int t = 0; t < rows; ++t)
  {
    const double dj = t - half_;
    const int hw = static_cast<int>(std::floor(std::sqrt(std::max(0.0, rs * rs - dj * dj))));
    const int count = (2 * hw + 1 + 3) / 4 * 4;
    row_lo_[static_cast<std::size_t>(t)] = half_ - hw;
    row_hi_[static_cast<std::size_t>(t)] = half_ - hw + count - 1;  // ≤ 2H + 3 < cols
  }
  gx_.resize(static_cast<std::size_t>(cols));
  gy_.resize(static_cast<std::size_t>(rows));
  prefix_x_.resize(static_cast<std::size_t>(cols) + 1);
  gxf_.resize(static_cast<std::size_t>(cols));
}

void EnergyAccumulator::reset()
{
  map_.clear();
  has_pending_ = false;
  started_ = false;
  next_index_ = 0;
  period_s_ = 0.0;
  outside_j_ = 0.0;
}

void EnergyAccumulator::process(const SpotChunk& chunk)
{
  const std::uint64_t n = chunk.samples.size();
  for (std::uint64_t k = 0; k < n; ++k)
  {
    const std::uint64_t index = chunk.first_index + k;
    if (started_ && index < next_index_)
    {
      continue;  // overlap or late chunk: this index was already accumulated
    }
    if (started_ && index > next_index_ && has_pending_)
    {
      finish();  // gap: the pending sample's successor is lost, deposit it where it stands
    }
    const SpotSample& s = chunk.samples[k];
    if (has_pending_ && pending_.power_w > 0.0)
    {
      deposit(pending_.actual, s.actual, pending_.power_w * period_s_);
    }
    pending_ = s;
    period_s_ = chunk.period_s;
    has_pending_ = true;
    started_ = true;
    next_index_ = index + 1;
  }
}

void EnergyAccumulator::finish()
{
  if (has_pending_ && pending_.power_w > 0.0)
  {
    deposit(pending_.actual, pending_.actual, pending_.power_w * period_s_);
  }
  has_pending_ = false;
}

void EnergyAccumulator::deposit(const Eigen::Vector2d& from, const Eigen::Vector2d& to, double energy_j)
{
  const Eigen::Vector2d delta = to - from;
  const double length = delta.norm();
  if (!from.allFinite() || !std::isfinite(length))
  {
    std::ostringstream msg;
    msg << "energy: non-finite spot position (" << from.x() << ", " << from.y() << ") -> (" << to.x() << ", "
        << to.y() << ") m while the laser is on";
    throw NumericalError(msg.str());
  }
  const double steps = std::max(1.0, std::ceil(length / substep_m_));
  if (steps > kMaxSubsteps)
  {
    std::ostringstream msg;
    msg << "energy: spot moved " << length << " m in one sample with the laser on (" << steps
        << " sub-steps): implausible";
    throw NumericalError(msg.str());
  }
  const int m = static_cast<int>(steps);
  const double e = energy_j / steps;
  for (int s = 0; s < m; ++s)
  {
    const double f = (s + 0.5) / steps;
    depositPoint(from.x() + f * delta.x(), from.y() + f * delta.y(), e);
  }
}

void EnergyAccumulator::depositPoint(double cx, double cy, double energy_j)
{
  const double p = map_.pixel();
  const Eigen::Vector2d& o = map_.origin();
  const int width = map_.width();
  const int height = map_.height();
  const int h = half_;

  // Pixel holding the centre (its centre is within p/2 of c on each axis).
  const double fx = std::floor((cx - o.x()) / p);
  const double fy = std::floor((cy - o.y()) / p);
  const int rows = 2 * h + 1;
  const int cols = static_cast<int>(gx_.size());  // stencil columns: [fx − H, fx − H + cols)
  if (fx - h + (cols - 1) < 0.0 || fx - h > width - 1.0 || fy + h < 0.0 || fy - h > height - 1.0)
  {
    outside_j_ += energy_j;  // whole stencil off the map
    return;
  }
  const int ic = static_cast<int>(fx);
  const int jc = static_cast<int>(fy);
  const int i0 = ic - h;  // map column of stencil column 0
  const int j0 = jc - h;

  // Separable weights: exp(-2|p-c|²/w²) = gx(x)·gy(y). Point sampling at the pixel centres: the
  // sampled sum Σ g·p² equals the integral πw²/2 up to the Poisson-sum (aliasing) term
  // 2·exp(-π²w²/(2p²)) per axis (1e-105 for w = 35 µm, p = 5 µm); the normalisation below makes
  // the deposit exact even for coarse pixels and the truncated tails.
  gaussianWeights(o.x() + (ic + 0.5) * p - cx, a_, p, q_, h, cols, gx_.data());
  gaussianWeights(o.y() + (jc + 0.5) * p - cy, a_, p, q_, h, rows, gy_.data());
  const double* gx = gx_.data();
  const double* gy = gy_.data();
  double* prefix = prefix_x_.data();
  float* gxf = gxf_.data();
  const int* row_lo = row_lo_.data();
  const int* row_hi = row_hi_.data();
  for (int k = 0; k < cols; ++k)
  {
    gxf[k] = static_cast<float>(gx[k]);
  }
  // prefix[k] = Σ_{m<k} gx[m], as four interleaved block scans (cols = 4L) and a fix-up: the
  // serial add chain is 4x shorter than a plain scan (it dominated the per-sub-step overhead).
  const int block = cols / 4;
  prefix[0] = 0.0;
  double s0 = 0.0, s1 = 0.0, s2 = 0.0, s3 = 0.0;
  for (int k = 0; k < block; ++k)
  {
    s0 += gx[k];
    s1 += gx[block + k];
    s2 += gx[2 * block + k];
    s3 += gx[3 * block + k];
    prefix[k + 1] = s0;
    prefix[block + k + 1] = s1;
    prefix[2 * block + k + 1] = s2;
    prefix[3 * block + k + 1] = s3;
  }
  for (int b = 1; b < 4; ++b)
  {
    const double offset = prefix[b * block];
    for (int k = b * block + 1; k <= (b + 1) * block; ++k)
    {
      prefix[k] += offset;
    }
  }
  double total = 0.0;  // total stencil weight
  for (int t = 0; t < rows; ++t)
  {
    total += gy[t] * (prefix[row_hi[t] + 1] - prefix[row_lo[t]]);
  }
  const double scale = energy_j / (p * p * total);  // [J/m²] per unit weight

  // Stencil columns/rows on the map.
  const int kmin = std::max(0, -i0);
  const int kmax = std::min(cols - 1, width - 1 - i0);
  const int tmin = std::max(0, -j0);
  const int tmax = std::min(rows - 1, height - 1 - j0);
  const bool inside = kmin == 0 && kmax == cols - 1 && tmin == 0 && tmax == rows - 1;
  double weight_in = 0.0;
  for (int t = tmin; t <= tmax; ++t)
  {
    const int klo = std::max(row_lo[t], kmin);
    const int khi = std::min(row_hi[t], kmax);
    if (klo > khi)
    {
      continue;
    }
    const float c = static_cast<float>(scale * gy[t]);
    axpyRow(map_.row(j0 + t) + (i0 + klo), gxf + klo, c, khi - klo + 1);
    if (!inside)
    {
      weight_in += gy[t] * (prefix[khi + 1] - prefix[klo]);
    }
  }
  if (!inside)
  {
    // Exactly the normalised weights of the stencil pixels that are off the map.
    outside_j_ += energy_j * ((total - weight_in) / total);
  }
}
}  // namespace scanhead
