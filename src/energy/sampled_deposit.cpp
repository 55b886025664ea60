/// \file sampled_deposit.cpp
/// \brief The point-sampled Gaussian spot (energy.method: sampled), SPEC §5.
#include "scanhead/energy/sampled_deposit.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "deposit_checks.hpp"
#include "row_kernels.hpp"
#include "scanhead/energy/spot_footprint.hpp"

namespace scanhead
{
using energy_detail::gaussianWeights;
using energy_detail::sumRow;

namespace
{

/// \brief w[k] = p[k], then p[k] *= r[k], k < n (n a multiple of 4): one row of the oblique
/// stencil and the power table for the next, in 16-byte vectors (GCC/Clang extensions, as axpyRow).
inline void copyAndAdvance(float* w, float* p, const float* r, int n)
{
  int k = 0;
#if defined(__GNUC__)
  typedef float Vec4 __attribute__((vector_size(16)));
  for (; k + 4 <= n; k += 4)
  {
    Vec4 pv, rv;
    std::memcpy(&pv, p + k, sizeof(Vec4));
    std::memcpy(&rv, r + k, sizeof(Vec4));
    std::memcpy(w + k, &pv, sizeof(Vec4));
    pv *= rv;
    std::memcpy(p + k, &pv, sizeof(Vec4));
  }
#endif
  for (; k < n; ++k)
  {
    w[k] = p[k];
    p[k] *= r[k];
  }
}

}  // namespace

SampledDeposit::SampledDeposit(const EnergyConfig& config)
  : config_(config)
  , footprint_(config_)
{
}

void SampledDeposit::deposit(TiledEnergyMap& map_, const SpotSample& from_sample, const Eigen::Vector2d& to,
                             double energy_j, double& outside_j_)
{
  const Eigen::Vector2d& from = from_sample.actual;
  const Eigen::Vector2d delta = to - from;
  const double length = delta.norm();
  energy_detail::requireFiniteSegment(from, to, length);
  const SpotFootprint fp = footprint_(from_sample.direction);
  const double steps = energy_detail::substepsOf(length, config_, fp);
  const int m = static_cast<int>(steps);
  const double e = energy_j / steps;
  for (int s = 0; s < m; ++s)
  {
    const double f = (s + 0.5) / steps;
    depositPoint(map_, from.x() + f * delta.x(), from.y() + f * delta.y(), e, fp, outside_j_);
  }
}

void SampledDeposit::depositPoint(TiledEnergyMap& map_, double cx, double cy, double energy_j, const SpotFootprint& fp,
                                  double& outside_j_)
{
  const double p = map_.pixel();
  const Eigen::Vector2d& o = map_.origin();
  const std::int64_t width = map_.width();
  const std::int64_t height = map_.height();
  // Rounded up to 1/8 pixel so that the row spans below are computed once per stencil size, not
  // once per sub-step (an oblique spot's radius changes a little with every sample).
  const double rs = energy_detail::stencilRadius(config_, fp, p);
  const int h = static_cast<int>(std::floor(rs));
  const int rows = 2 * h + 1;
  const int cols = (rows + 3 + 3) / 4 * 4;  // room for the widened rows, a multiple of 4

  // Pixel holding the centre (its centre is within p/2 of c on each axis).
  const double fx = std::floor((cx - o.x()) / p);
  const double fy = std::floor((cy - o.y()) / p);
  if (fx - h + (cols - 1) < 0.0 || fx - h > static_cast<double>(width - 1) || fy + h < 0.0 ||
      fy - h > static_cast<double>(height - 1))
  {
    outside_j_ += energy_j;  // whole stencil off the map
    return;
  }
  const std::int64_t i0 = static_cast<std::int64_t>(fx) - h;  // map column of stencil column 0
  const std::int64_t j0 = static_cast<std::int64_t>(fy) - h;
  const double dxc = o.x() + (static_cast<double>(i0 + h) + 0.5) * p - cx;  // centre pixel − c [m]
  const double dyc = o.y() + (static_cast<double>(j0 + h) + 0.5) * p - cy;

  gy_.resize(static_cast<std::size_t>(rows));
  row_sum_.resize(static_cast<std::size_t>(rows));
  gx_.resize(static_cast<std::size_t>(cols));
  prefix_.resize(static_cast<std::size_t>(cols) + 1);
  const bool separable = fp.qxy == 0.0;
  gxf_.resize(static_cast<std::size_t>(separable ? cols : rows * cols));
  // Row t covers the columns within rs of the centre, |di| ≤ floor(sqrt(rs² − dj²)), widened on the
  // right to a multiple of 4 (any set of pixels holding the disc will do: the normalisation makes it
  // conserve energy exactly).
  if (rs != span_radius_)
  {
    span_radius_ = rs;
    span_lo_.resize(static_cast<std::size_t>(rows));
    span_hi_.resize(static_cast<std::size_t>(rows));
    for (int t = 0; t < rows; ++t)
    {
      const double dj = t - h;
      const int hw = static_cast<int>(std::floor(std::sqrt(std::max(0.0, rs * rs - dj * dj))));
      span_lo_[static_cast<std::size_t>(t)] = h - hw;
      span_hi_[static_cast<std::size_t>(t)] = h - hw + (2 * hw + 1 + 3) / 4 * 4 - 1;  // ≤ 2H + 3 < cols
    }
  }
  auto row_span = [&](int t, int& lo, int& hi) {
    lo = span_lo_[static_cast<std::size_t>(t)];
    hi = span_hi_[static_cast<std::size_t>(t)];
  };
  double total = 0.0;
  // With x_k = dxc + (k − H)p, y_t = dyc + (t − H)p: W = exp(−qxx x² − 2 qxy x y − qyy y²)
  //   = exp(−qyy y_t²) · exp(−qxx x_k² − 2 qxy x_k dyc) · E_k^(t − H),  E_k = exp(−2 qxy p x_k):
  // rows gy, columns gx (∝ a Gaussian centred at −(qxy/qxx)·dyc), and for the oblique spot a power
  // table P_k = E_k^(t − H) updated row by row (one multiply a pixel, no exponential per row).
  gaussianWeights(dyc, fp.qyy, p, std::exp(-2.0 * fp.qyy * p * p), h, rows, gy_.data());
  gaussianWeights(dxc + fp.qxy / fp.qxx * dyc, fp.qxx, p, std::exp(-2.0 * fp.qxx * p * p), h, cols, gx_.data());
  if (separable)
  {
    // One row of weights for the whole stencil, and its prefix sums for the rows' totals.
    prefix_[0] = 0.0;
    for (int k = 0; k < cols; ++k)
    {
      prefix_[static_cast<std::size_t>(k) + 1] =
          prefix_[static_cast<std::size_t>(k)] + gx_[static_cast<std::size_t>(k)];
      gxf_[static_cast<std::size_t>(k)] = static_cast<float>(gx_[static_cast<std::size_t>(k)]);
    }
    for (int t = 0; t < rows; ++t)
    {
      int lo = 0, hi = 0;
      row_span(t, lo, hi);
      row_sum_[static_cast<std::size_t>(t)] =
          gy_[static_cast<std::size_t>(t)] *
          (prefix_[static_cast<std::size_t>(hi) + 1] - prefix_[static_cast<std::size_t>(lo)]);
      total += row_sum_[static_cast<std::size_t>(t)];
    }
  }
  else
  {
    power_.resize(static_cast<std::size_t>(cols));
    ratio_.resize(static_cast<std::size_t>(cols));
    // E_k and E_k^(−H) are geometric in k: 4 exponentials, then products outwards from the centre.
    const double e_step = std::exp(-2.0 * fp.qxy * p * p), p_step = std::exp(2.0 * fp.qxy * p * p * h);
    double e_up = std::exp(-2.0 * fp.qxy * p * dxc), p_up = std::exp(2.0 * fp.qxy * p * h * dxc);
    double e_down = e_up, p_down = p_up;
    for (int up = h, down = h; up < cols; ++up, --down)
    {
      ratio_[static_cast<std::size_t>(up)] = static_cast<float>(e_up);
      power_[static_cast<std::size_t>(up)] = static_cast<float>(p_up * gx_[static_cast<std::size_t>(up)]);
      e_up *= e_step;
      p_up *= p_step;
      if (down >= 0)
      {
        ratio_[static_cast<std::size_t>(down)] = static_cast<float>(e_down);
        power_[static_cast<std::size_t>(down)] = static_cast<float>(p_down * gx_[static_cast<std::size_t>(down)]);
        e_down /= e_step;
        p_down /= p_step;
      }
    }
    for (int t = 0; t < rows; ++t)
    {
      int lo = 0, hi = 0;
      row_span(t, lo, hi);
      float* w = gxf_.data() + static_cast<std::size_t>(t) * cols;
      copyAndAdvance(w, power_.data(), ratio_.data(), cols);
      row_sum_[static_cast<std::size_t>(t)] = gy_[static_cast<std::size_t>(t)] * sumRow(w + lo, hi - lo + 1);
      total += row_sum_[static_cast<std::size_t>(t)];
    }
  }
  auto row_floats = [&](int t) { return gxf_.data() + (separable ? 0 : static_cast<std::size_t>(t) * cols); };
  auto span_sum = [&](int t, int lo, int hi) {
    if (separable)
      return prefix_[static_cast<std::size_t>(hi) + 1] - prefix_[static_cast<std::size_t>(lo)];
    double sum = 0.0;
    for (int k = lo; k <= hi; ++k)
      sum += row_floats(t)[k];
    return sum;
  };
  const double scale = energy_j / (p * p * total);  // [J/m²] per unit weight

  double weight_in = 0.0;
  for (int t = 0; t < rows; ++t)
  {
    const std::int64_t row = j0 + t;
    if (row < 0 || row >= height)
      continue;
    int lo = 0, hi = 0;
    row_span(t, lo, hi);
    const int klo = static_cast<int>(std::max<std::int64_t>(lo, -i0));
    const int khi = static_cast<int>(std::min<std::int64_t>(hi, width - 1 - i0));
    if (klo > khi)
      continue;
    const float c = static_cast<float>(scale * gy_[static_cast<std::size_t>(t)]);
    map_.addRow(row, i0 + klo, row_floats(t) + klo, c, khi - klo + 1);
    weight_in += klo == lo && khi == hi ? row_sum_[static_cast<std::size_t>(t)]
                                        : gy_[static_cast<std::size_t>(t)] * span_sum(t, klo, khi);
  }
  if (weight_in < total)
  {
    // The normalised weights of the stencil pixels that are off the map.
    outside_j_ += energy_j * ((total - weight_in) / total);
  }
}
}  // namespace scanhead
