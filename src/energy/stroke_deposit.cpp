/// \file stroke_deposit.cpp
/// \brief The closed-form deposit of a straight constant-velocity stroke, row by row.
#include "scanhead/energy/stroke_deposit.hpp"

#include <algorithm>
#include <cmath>

#include "row_kernels.hpp"
#include "scanhead/energy/segment_integral.hpp"

namespace scanhead
{
namespace
{
constexpr double kErfSaturated = 6.0;  // erf(±6) = ±1 in double (erfc 6 = 2.2e-17 < half an ulp of 1)

/// \brief erf by piecewise cubic Hermite interpolation on [0, 6) in steps of h = 1/64, from erf and its derivative
/// 2/√π·e^{−x²} at the knots (|error| ≤ h⁴/384·max|erf⁗| = 1.6e-10·5.9 < 1e-9), ±1 beyond: 2.3 ns instead of ~20
/// for std::erf, on a table of 12 KiB (in L1). Odd: erf(−x) = −erf(x).
class ErfTable
{
public:
  static constexpr int kPerUnit = 64;
  ErfTable()
  {
    const double h = 1.0 / kPerUnit;
    for (int i = 0; i < kIntervals; ++i)
    {
      const double x0 = i * h, x1 = (i + 1) * h;
      const double f0 = std::erf(x0), f1 = std::erf(x1);
      const double d0 = h * 2.0 / std::sqrt(M_PI) * std::exp(-x0 * x0),
                   d1 = h * 2.0 / std::sqrt(M_PI) * std::exp(-x1 * x1);
      double* c = coefficients_ + 4 * i;
      c[0] = f0;
      c[1] = d0;
      c[2] = 3.0 * (f1 - f0) - 2.0 * d0 - d1;
      c[3] = 2.0 * (f0 - f1) + d0 + d1;
    }
  }
  double operator()(double x) const
  {
    const double a = std::abs(x);
    if (!(a < kErfSaturated))
      return std::copysign(1.0, x);
    const double scaled = a * kPerUnit;
    const int i = static_cast<int>(scaled);
    const double t = scaled - i;
    const double* c = coefficients_ + 4 * i;
    return std::copysign(c[0] + t * (c[1] + t * (c[2] + t * c[3])), x);
  }

private:
  static constexpr int kIntervals = static_cast<int>(kErfSaturated) * kPerUnit;
  double coefficients_[4 * kIntervals];
};

const ErfTable& erfTable()
{
  static const ErfTable table;
  return table;
}

// √A up to this: the erf difference by 4-point Gauss–Legendre (error ≤ 9.4e-7·√A⁹·… ≤ 2e-9 of the bracket at 0.5).
constexpr double kShortStroke = 0.5;

/// \brief Narrows [lo, hi] to the x with c_lo ≤ α·x + β ≤ c_hi.
void clampLinear(double alpha, double beta, double c_lo, double c_hi, double& lo, double& hi)
{
  if (alpha == 0.0)
  {
    if (beta < c_lo || beta > c_hi)
      hi = lo - 1.0;  // empty
    return;
  }
  double a = (c_lo - beta) / alpha, b = (c_hi - beta) / alpha;
  if (a > b)
    std::swap(a, b);
  lo = std::max(lo, a);
  hi = std::min(hi, b);
}

/// \brief Widens [lo, hi] by the chord of the disc (centre c, radius R) at height y.
void addDisc(const Eigen::Vector2d& c, double radius, double y, double& lo, double& hi)
{
  const double dy = y - c.y();
  if (std::abs(dy) > radius)
    return;
  const double half = std::sqrt(radius * radius - dy * dy);
  lo = std::min(lo, c.x() - half);
  hi = std::max(hi, c.x() + half);
}

/// \brief out[k] = Σ_i amp[i]·exp(−e[i] − α (k − centre[i])²), k < n, for nodes ≤ 4 Gaussians of one curvature
/// α ≥ 0 (q = e^{−2α} given).
///
/// The recurrence of gaussianWeights for each, interleaved: from the column nearest the centres' mean outwards,
/// g_{k+1} = g_k·r_k, r_{k+1} = r_k·q (leftwards with q/r); two exponentials a node a row, 2 multiplications a node a
/// pixel, relative error ~n·1e-16; a Gaussian whose start underflows only meets smaller values further out.
void gaussianSumRow(int nodes, const double* amp, const double* e, const double* centre, double alpha, double q, int n,
                    double* out)
{
  double mean = 0.0;
  for (int i = 0; i < nodes; ++i)
    mean += centre[i];
  const int half = static_cast<int>(std::clamp(std::round(mean / nodes), 0.0, static_cast<double>(n - 1)));
  double g[4], r[4], gl[4], rl[4];
  double sum = 0.0;
  for (int i = 0; i < nodes; ++i)
  {
    const double d = half - centre[i];
    g[i] = gl[i] = amp[i] * std::exp(-e[i] - alpha * d * d);
    r[i] = std::exp(-alpha * (2.0 * d + 1.0));
    rl[i] = q / r[i];  // exp(−α(−2d + 1))
    sum += g[i];
  }
  out[half] = sum;
  for (int k = half + 1; k < n; ++k)
  {
    sum = 0.0;
    for (int i = 0; i < nodes; ++i)
    {
      g[i] *= r[i];
      r[i] *= q;
      sum += g[i];
    }
    out[k] = sum;
  }
  for (int k = half - 1; k >= 0; --k)
  {
    sum = 0.0;
    for (int i = 0; i < nodes; ++i)
    {
      gl[i] *= rl[i];
      rl[i] *= q;
      sum += gl[i];
    }
    out[k] = sum;
  }
}

// Gauss–Legendre nodes and weights on [0, 1] (Abramowitz & Stegun 25.4.30, n = 4).
constexpr double kGaussNodes[4] = {0.5 * (1.0 - 0.8611363115940526), 0.5 * (1.0 - 0.3399810435848563),
                                   0.5 * (1.0 + 0.3399810435848563), 0.5 * (1.0 + 0.8611363115940526)};
constexpr double kGaussWeights[4] = {0.5 * 0.3478548451374538, 0.5 * 0.6521451548625461, 0.5 * 0.6521451548625461,
                                     0.5 * 0.3478548451374538};
}  // namespace

StrokeDeposit::StrokeDeposit(const EnergyConfig& config)
  : config_(config)
{
}

void StrokeDeposit::deposit(TiledEnergyMap& map, const Stroke& stroke, double& outside_j)
{
  const double energy_j = stroke.energy();
  const SpotFootprint& fp = stroke.footprint;
  const Eigen::Vector2d d = stroke.displacement();
  const SegmentIntegral si(fp, d);
  const double p = map.pixel();
  const Eigen::Vector2d& o = map.origin();
  const std::int64_t width = map.width(), height = map.height();
  const double radius = config_.truncation_radii * fp.major_radius_m;
  const Eigen::Vector2d c0 = stroke.start, c1 = stroke.start + d;

  // Pixel centres o + (i + 0.5)p within [a, b]: i from ceil((a − o)/p − 0.5) to floor((b − o)/p − 0.5).
  auto first = [p](double a, double origin) { return std::ceil((a - origin) / p - 0.5); };
  auto last = [p](double b, double origin) { return std::floor((b - origin) / p - 0.5); };
  const double row_lo = first(std::min(c0.y(), c1.y()) - radius, o.y());
  const double row_hi = last(std::max(c0.y(), c1.y()) + radius, o.y());
  const double col_lo = first(std::min(c0.x(), c1.x()) - radius, o.x());
  const double col_hi = last(std::max(c0.x(), c1.x()) + radius, o.x());
  if (row_hi < 0.0 || row_lo > static_cast<double>(height - 1) || col_hi < 0.0 ||
      col_lo > static_cast<double>(width - 1))
  {
    outside_j += energy_j;  // the whole capsule off the map
    return;
  }

  const double length = d.norm();
  const Eigen::Vector2d t = length > 0.0 ? Eigen::Vector2d(d / length) : Eigen::Vector2d(1.0, 0.0);
  const Eigen::Vector2d nrm(-t.y(), t.x());
  // Per-stroke constants of the row recurrences (curvatures along a row, in columns).
  const double ds_row = si.m.x() * p, du_row = si.g.x() * p;
  const double alpha_stationary = si.qxx * p * p, q_stationary = std::exp(-2.0 * alpha_stationary);
  const double alpha = ds_row * ds_row + du_row * du_row, q_short = std::exp(-2.0 * alpha);  // α > 0: m, g independent
  const double alpha_cross = ds_row * ds_row, q_cross = std::exp(-2.0 * alpha_cross);
  rows_.clear();
  std::size_t used = 0;
  double total = 0.0;
  for (double jr = row_lo; jr <= row_hi; jr += 1.0)
  {
    const double y = o.y() + (jr + 0.5) * p;
    // The capsule's chord at y: the discs at both ends and the band |n·r| ≤ R, 0 ≤ t·r ≤ L between.
    double lo = INFINITY, hi = -INFINITY;
    addDisc(c0, radius, y, lo, hi);
    addDisc(c1, radius, y, lo, hi);
    if (length > 0.0)
    {
      double blo = -INFINITY, bhi = INFINITY;
      const double ry = y - c0.y();
      clampLinear(nrm.x(), nrm.y() * ry, -radius, radius, blo, bhi);
      clampLinear(t.x(), t.y() * ry, 0.0, length, blo, bhi);
      if (blo <= bhi)
      {
        lo = std::min(lo, c0.x() + blo);
        hi = std::max(hi, c0.x() + bhi);
      }
    }
    if (!(lo <= hi))
      continue;
    const double i_lo = first(lo, o.x()), i_hi = last(hi, o.x());
    if (i_hi < i_lo)
      continue;
    const int n = static_cast<int>(i_hi - i_lo) + 1;
    if (weights_.size() < used + static_cast<std::size_t>(n))
      weights_.resize(std::max(2 * weights_.size(), used + static_cast<std::size_t>(n)));
    if (cross_.size() < static_cast<std::size_t>(n))
      cross_.resize(static_cast<std::size_t>(n));
    float* w = weights_.data() + used;
    // x − c0.x of column i_lo + k is x0 + k·p.
    const double x0 = o.x() + (i_lo + 0.5) * p - c0.x();
    const double ry = y - c0.y();
    if (si.stationary)
    {
      // exp(−rᵀQr) = exp(−(det Q/q_xx)·Y²)·exp(−q_xx(X − X*)²), X* = −q_xy·Y/q_xx (r from the midpoint).
      const double yy = ry - si.centre.y();
      const double xs = si.centre.x() - si.qxy / si.qxx * yy;  // X* in c0's frame
      const double amp = 1.0, e = (si.qxx * si.qyy - si.qxy * si.qxy) / si.qxx * yy * yy;
      const double centre = (xs - x0) / p;
      gaussianSumRow(1, &amp, &e, &centre, alpha_stationary, q_stationary, n, cross_.data());
      for (int k = 0; k < n; ++k)
        w[k] = static_cast<float>(cross_[static_cast<std::size_t>(k)]);
    }
    else if (si.sqrt_a <= kShortStroke)
    {
      // A short stroke: erf(u) − erf(u − √A) = (2/√π)∫ e^{−x²} over [u − √A, u] by 4-point Gauss–Legendre, so
      // W = (2/√π)·√A·Σ_i w_i·exp(−s² − (u − √A τ_i)²): along the row each term is one Gaussian in k.
      const double s0 = si.m.x() * x0 + si.m.y() * ry, ds = si.m.x() * p;
      const double u0 = si.g.x() * x0 + si.g.y() * ry, du = si.g.x() * p;
      double amp[4], e[4], centre[4];
      for (int i = 0; i < 4; ++i)
      {
        // s_k² + (u_k − c)² = α(k − k*)² + e_min, k* = −(s0·ds + (u0 − c)·du)/α.
        const double uc = u0 - si.sqrt_a * kGaussNodes[i];
        const double b = s0 * ds + uc * du;
        centre[i] = -b / alpha;
        e[i] = std::max(0.0, s0 * s0 + uc * uc - b * b / alpha);
        amp[i] = 2.0 / std::sqrt(M_PI) * si.sqrt_a * kGaussWeights[i];
      }
      gaussianSumRow(4, amp, e, centre, alpha, q_short, n, cross_.data());
      for (int k = 0; k < n; ++k)
        w[k] = static_cast<float>(cross_[static_cast<std::size_t>(k)]);
    }
    else
    {
      // s = mᵀr = m_x·x + m_y·Y along the row (slope m_x·p per column); u = gᵀr likewise.
      const double s0 = si.m.x() * x0 + si.m.y() * ry, ds = si.m.x() * p;
      const double one = 1.0;
      double centre = 0.0, e = 0.0;
      if (ds != 0.0)
        centre = -s0 / ds;  // s = ds·(k − centre)
      else
        e = s0 * s0;
      gaussianSumRow(1, &one, &e, &centre, alpha_cross, q_cross, n, cross_.data());
      const double u0 = si.g.x() * x0 + si.g.y() * ry, du = si.g.x() * p, sa = si.sqrt_a;
      const ErfTable& erf = erfTable();
      // u is monotonic along the row, so the saturated pixels (bracket exactly 2) form one run: fill the row as if
      // saturated (a vector loop), then evaluate the bracket from both ends inwards until it saturates.
      const double* cross = cross_.data();
      for (int k = 0; k < n; ++k)
        w[k] = static_cast<float>(cross[k] * 2.0);
      auto saturated = [&](double u) { return u > kErfSaturated && sa - u > kErfSaturated; };
      auto bracket = [&](double u) {
        return u < -kErfSaturated || u - sa > kErfSaturated ? 0.0 : erf(sa - u) + erf(u);
      };
      int k = 0;
      for (; k < n; ++k)
      {
        const double u = u0 + k * du;
        if (saturated(u))
          break;
        w[k] = static_cast<float>(cross[k] * bracket(u));
      }
      for (int j = n - 1; j > k; --j)
      {
        const double u = u0 + j * du;
        if (saturated(u))
          break;
        w[j] = static_cast<float>(cross[j] * bracket(u));
      }
    }
    Row r;
    r.row = static_cast<std::int64_t>(jr);
    r.col = static_cast<std::int64_t>(i_lo);
    r.n = n;
    r.offset = used;
    r.sum = energy_detail::sumRow(w, n);
    total += r.sum;
    rows_.push_back(r);
    used += static_cast<std::size_t>(n);
  }
  pixels_ += used;

  if (!(total > 0.0))
  {
    // No pixel centre in reach of the spot (pixels far larger than it): the pixel holding the midpoint takes it all.
    const Eigen::Vector2d mid = c0 + 0.5 * d;
    const double i = std::floor((mid.x() - o.x()) / p), j = std::floor((mid.y() - o.y()) / p);
    if (i < 0.0 || j < 0.0 || i > static_cast<double>(width - 1) || j > static_cast<double>(height - 1))
    {
      outside_j += energy_j;
      return;
    }
    const float one = 1.0f;
    map.addRow(static_cast<std::int64_t>(j), static_cast<std::int64_t>(i), &one, static_cast<float>(energy_j / (p * p)),
               1);
    return;
  }
  const float scale = static_cast<float>(energy_j / (p * p * total));  // [J/m²] per unit weight
  double weight_in = 0.0;
  for (const Row& r : rows_)
  {
    if (r.row < 0 || r.row >= height)
      continue;
    const std::int64_t klo = std::max<std::int64_t>(0, -r.col);
    const std::int64_t khi = std::min<std::int64_t>(r.n - 1, width - 1 - r.col);
    if (klo > khi)
      continue;
    const float* w = weights_.data() + r.offset;
    const int count = static_cast<int>(khi - klo + 1);
    map.addRow(r.row, r.col + klo, w + klo, scale, count);
    weight_in += count == r.n ? r.sum : energy_detail::sumRow(w + klo, count);
  }
  if (weight_in < total)
    outside_j += energy_j * ((total - weight_in) / total);
}
}  // namespace scanhead
