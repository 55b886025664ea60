/// \file stroke_deposit.cpp
/// \brief The closed-form deposit of a straight constant-velocity stroke, row by row.
#include "scanhead/energy/stroke_deposit.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "lane_math.hpp"
#include "row_kernels.hpp"
#include "scanhead/energy/segment_integral.hpp"

namespace scanhead
{
namespace
{
constexpr double kErfSaturated = 6.0;  // erf(±6) = ±1 in double (erfc 6 = 2.2e-17 < half an ulp of 1)

// √A up to this: the erf difference by 4-point Gauss–Legendre, one exponential a pixel instead of the erf form's
// exponential and two erfs (error ≤ 9.5e-7·√A⁹: measured worst over u, 9.2e-7 of the stroke's peak bracket at √A = 1,
// 3.7e-9 at 0.5: no more than the lane erf's 4e-6). √A = 1 is 25 µm at w = 35 µm: 2-sample strokes at 1 m/s.
constexpr double kShortStroke = 1.0;

/// Blocks between two exact evaluations of GaussianSteps (bounds the growth of the products' rounding).
constexpr int kAnchorBlocks = 8;

/// \brief e^{−Q(k)} on the 8 lanes of consecutive blocks of a row, Q(k) = (s0 + k·ds)² + (u0 + k·du)² (u0 = du = 0:
/// the cross factor e^{−s²} alone).
///
/// Q is quadratic in k, so e^{−Q} is geometric to second order: with D(k) = Q(k + 8) − Q(k) and the block's first
/// column k, E ← E·e^{−D}, e^{−D} ← e^{−D}·q, q = e^{−128A}, A = ds² + du². Two exponentials every kAnchorBlocks
/// blocks (each argument formed in double at the block's first column, the lanes added in float, as the exact
/// evaluation does) and two products a block in between, instead of one exponential a block. Error: the float
/// rounding of D (|D| ≲ 20 in the capsule: ~1e-6) compounds over ≤ kAnchorBlocks products, ≤ ~8e-6 relative to the
/// value and ~1e-6 of the stroke's peak (where D is large the value is small), inside float's precision of the
/// exact form's own arguments and far inside issue 13's 2e-3.
struct GaussianSteps
{
  double s0 = 0.0, ds = 0.0, u0 = 0.0, du = 0.0;
  energy_detail::F8 e, r;
  energy_detail::F8 q;
  int left = 0;  ///< blocks before the next anchor

  /// \param[in] q_block e^{−128(ds² + du²)}, rounded to float (gaussianRatio: once a stroke)
  SCANHEAD_LANE_INLINE GaussianSteps(double s_first, double s_step, double u_first, double u_step, float q_block)
    : s0(s_first)
    , ds(s_step)
    , u0(u_first)
    , du(u_step)
    , q(energy_detail::splat(q_block))
  {
  }
  /// \brief The lanes of the block starting at column \p k0 (blocks in order, 8 columns apart; the row's last block
  /// starts before \p end).
  SCANHEAD_LANE_INLINE energy_detail::F8 next(int k0, int end)
  {
    using namespace energy_detail;
    if (left == 0)
    {
      const F8 lane = laneIndex();
      const double s = s0 + k0 * ds, u = u0 + k0 * du;
      const F8 sl = splat(static_cast<float>(s)) + splat(static_cast<float>(ds)) * lane;
      const F8 ul = splat(static_cast<float>(u)) + splat(static_cast<float>(du)) * lane;
      e = expNeg(sl * sl + ul * ul);
      if (end - k0 <= 8)
        return e;  // the last block: no ratio needed
      // D at the lanes: 16(s·ds + u·du) + 64A + 16A·l.
      const double a = ds * ds + du * du;
      r = expNeg(splat(static_cast<float>(16.0 * (s * ds + u * du) + 64.0 * a)) +
                 splat(static_cast<float>(16.0 * a)) * lane);
      left = kAnchorBlocks;
    }
    const F8 value = e;
    e = e * r;
    r = r * q;
    --left;
    return value;
  }
};

/// \brief GaussianSteps' q for the steps \p ds, \p du of a stroke's rows.
float gaussianRatio(double ds, double du)
{
  return static_cast<float>(std::exp(-128.0 * (ds * ds + du * du)));
}

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

/// \brief exp(−e − α(k − centre)²) along a row, α ≥ 0: a dwell's footprint on one row.
struct RowGaussian
{
  double e = 0.0, centre = 0.0;
  double alpha = 0.0;
};

/// \brief w[k] = the RowGaussian at column k, k < n rounded up to a multiple of 8 (w has room for it).
///
/// 8 columns a block, every exponential evaluated (lane_math.hpp: no recurrence, so no error growth along a row);
/// k − centre is formed in double and rounded once, so a row far from the origin keeps float's relative precision.
__attribute__((target_clones("avx2", "default"))) double rowGaussianLanes(const RowGaussian& g, int n, float* w)
{
  using namespace energy_detail;
  const F8 lane = laneIndex();
  F8 total = splat(0.0f);
  const F8 alpha = splat(static_cast<float>(g.alpha));
  for (int k0 = 0; k0 < n; k0 += 8)
  {
    const F8 t = splat(static_cast<float>(k0 - g.centre)) + lane;
    const F8 sum = expNeg(splat(static_cast<float>(g.e)) + alpha * (t * t));
    std::memcpy(w + k0, &sum, sizeof sum);
    accumulate(total, sum, n - k0);
  }
  return laneSum(total);
}

/// \brief A short stroke along a row: s_k = s0 + k·ds, u_k = u0 + k·du, and the 4-point Gauss–Legendre form
/// W = Σ_i a_i·exp(−s² − (u − c_i)²), c_i = √A·τ_i, a_i = (2/√π)·√A·w_i.
struct ShortRow
{
  double s0 = 0.0, ds = 0.0, u0 = 0.0, du = 0.0;
  double c[4] = {}, a[4] = {};
  // The same on every row of a stroke (computed once a stroke):
  float lanes[4][8] = {};  ///< e^{2c_i·du·l}, l = 0..7
  float advance[4] = {};   ///< e^{16 c_i du}
  float gauss_q = 0.0f;    ///< gaussianRatio(ds, du)
};

/// \brief w[k] for the ShortRow, k < n rounded up to a multiple of 8.
///
/// s² + (u − c)² = (s² + u²) − 2cu + c², so W = exp(−s² − u²)·Σ_i a_i e^{−c_i²}·e^{2c_i u}: the common Gaussian by
/// GaussianSteps, and each node's e^{2c_i u_k} = [a_i e^{2c_i u0 − c_i²}]·e^{2c_i du·l}·e^{16 c_i du·b} (block b, lane
/// l): one scalar exponential a node a row, the lane and block factors once a stroke (relative error ~1e-7 a block;
/// a short stroke's row has ≤ (2R + √A·w)/p pixels, a few blocks). With √A ≤ 1 (kShortStroke) |2c_i u| ≤ 2|u|, a
/// few units in the capsule: far inside float's range.
__attribute__((target_clones("avx2", "default"))) double shortRowLanes(const ShortRow& r, int n, float* w)
{
  using namespace energy_detail;
  F8 total = splat(0.0f);
  // a_i·e^{2c_i u0 − c_i²} of the four nodes in the first lanes of one exponential (arguments rounded once).
  const F8 row_factors =
      expNeg(F8{static_cast<float>(r.c[0] * (r.c[0] - 2.0 * r.u0)), static_cast<float>(r.c[1] * (r.c[1] - 2.0 * r.u0)),
                static_cast<float>(r.c[2] * (r.c[2] - 2.0 * r.u0)), static_cast<float>(r.c[3] * (r.c[3] - 2.0 * r.u0)),
                0.0f, 0.0f, 0.0f, 0.0f});
  F8 node[4], advance[4];
#pragma GCC unroll 4
  for (int i = 0; i < 4; ++i)
  {
    F8 lanes;
    std::memcpy(&lanes, r.lanes[i], sizeof lanes);
    node[i] = splat(static_cast<float>(r.a[i]) * row_factors[i]) * lanes;
    advance[i] = splat(r.advance[i]);
  }
  GaussianSteps gaussian(r.s0, r.ds, r.u0, r.du, r.gauss_q);
  for (int k0 = 0; k0 < n; k0 += 8)
  {
    const F8 value = gaussian.next(k0, n) * ((node[0] + node[1]) + (node[2] + node[3]));
    std::memcpy(w + k0, &value, sizeof value);
    accumulate(total, value, n - k0);
    for (int i = 0; i < 4; ++i)
      node[i] *= advance[i];
  }
  return laneSum(total);
}

/// \brief The erf form along a row: s_k = s0 + k·ds, u_k = u0 + k·du, W = exp(−s²)·[erf(√A − u) + erf(u)].
struct ErfRow
{
  double s0 = 0.0, ds = 0.0, u0 = 0.0, du = 0.0, sqrt_a = 0.0;
  float gauss_q = 0.0f;  ///< gaussianRatio(ds, 0): the same on every row of a stroke
};

/// \brief w[k] = W at columns k ∈ [begin, end) rounded up to a multiple of 8 from begin; \p saturated: the bracket is
/// 2 there (|u| and |√A − u| > 6), only the cross factor is evaluated. Each block's s, u and √A − u are formed in
/// double at its first column, the lanes add k·ds in float: the arguments keep float's precision near zero however
/// long the stroke. The bracket is clamped at 0 (erf(√A − u) ≥ −erf(u) exactly; rounding could make it −1e-7).
__attribute__((target_clones("avx2", "default"))) double erfRowLanes(const ErfRow& r, int begin, int end,
                                                                     bool saturated, float* w)
{
  using namespace energy_detail;
  F8 total = splat(0.0f);
  const F8 du = splat(static_cast<float>(r.du)) * laneIndex();
  GaussianSteps gaussian(r.s0, r.ds, 0.0, 0.0, r.gauss_q);
  for (int k0 = begin; k0 < end; k0 += 8)
  {
    const F8 cross = gaussian.next(k0, end);
    F8 value;
    if (saturated)
      value = splat(2.0f) * cross;
    else
    {
      const double u_first = r.u0 + k0 * r.du;
      const F8 u = splat(static_cast<float>(u_first)) + du;
      const F8 v = splat(static_cast<float>(r.sqrt_a - u_first)) - du;
      F8 bracket = erfLanes(v) + erfLanes(u);
      bracket = bracket > splat(0.0f) ? bracket : splat(0.0f);
      value = cross * bracket;
    }
    std::memcpy(w + k0, &value, sizeof value);
    accumulate(total, value, end - k0);
  }
  return laneSum(total);
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

void StrokeDeposit::weigh(const TiledEnergyMap& map, const Stroke& stroke, StrokeWeights& out) const
{
  out.energy_j = stroke.energy();
  out.off_map = false;
  out.rows.clear();
  out.total = 0.0;
  out.midpoint = stroke.start + 0.5 * stroke.displacement();
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
    out.off_map = true;  // the whole capsule off the map
    return;
  }

  const double length = d.norm();
  const Eigen::Vector2d t = length > 0.0 ? Eigen::Vector2d(d / length) : Eigen::Vector2d(1.0, 0.0);
  const Eigen::Vector2d nrm(-t.y(), t.x());
  // Per-stroke constants of the row recurrences (curvatures along a row, in columns; a short stroke's nodes).
  const double alpha_stationary = si.qxx * p * p;
  ShortRow short_row;
  if (!si.stationary && si.sqrt_a <= kShortStroke)
  {
    short_row.ds = si.m.x() * p;
    short_row.du = si.g.x() * p;
    for (int i = 0; i < 4; ++i)
    {
      short_row.c[i] = si.sqrt_a * kGaussNodes[i];
      short_row.a[i] = 2.0 / std::sqrt(M_PI) * si.sqrt_a * kGaussWeights[i];
      short_row.advance[i] = static_cast<float>(std::exp(16.0 * short_row.c[i] * short_row.du));
      const energy_detail::F8 lanes = energy_detail::expNeg(
          energy_detail::splat(static_cast<float>(-2.0 * short_row.c[i] * short_row.du)) * energy_detail::laneIndex());
      std::memcpy(short_row.lanes[i], &lanes, sizeof lanes);
    }
    short_row.gauss_q = gaussianRatio(short_row.ds, short_row.du);
  }
  const float erf_q = !si.stationary && si.sqrt_a > kShortStroke ? gaussianRatio(si.m.x() * p, 0.0) : 0.0f;
  std::vector<float>& weights = out.weights;
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
    // The lane kernels write whole blocks of 8: room for the last one (the next row overwrites the excess).
    const std::size_t room = used + static_cast<std::size_t>(n) + 8;
    if (weights.size() < room)
      weights.resize(std::max(2 * weights.size(), room));
    float* w = weights.data() + used;
    // x − c0.x of column i_lo + k is x0 + k·p.
    const double x0 = o.x() + (i_lo + 0.5) * p - c0.x();
    const double ry = y - c0.y();
    double row_sum = 0.0;  // Σ of the row's float weights, from the kernels
    if (si.stationary)
    {
      // exp(−rᵀQr) = exp(−(det Q/q_xx)·Y²)·exp(−q_xx(X − X*)²), X* = −q_xy·Y/q_xx (r from the midpoint).
      const double yy = ry - si.centre.y();
      const double xs = si.centre.x() - si.qxy / si.qxx * yy;  // X* in c0's frame
      RowGaussian g;
      g.e = (si.qxx * si.qyy - si.qxy * si.qxy) / si.qxx * yy * yy;
      g.centre = (xs - x0) / p;
      g.alpha = alpha_stationary;
      row_sum = rowGaussianLanes(g, n, w);
    }
    else if (si.sqrt_a <= kShortStroke)
    {
      // A short stroke: erf(u) − erf(u − √A) = (2/√π)∫ e^{−x²} over [u − √A, u] by 4-point Gauss–Legendre, so
      // W = (2/√π)·√A·Σ_i w_i·exp(−s² − (u − √A τ_i)²) (shortRowLanes).
      ShortRow& g = short_row;  // the stroke's constants, this row's start
      g.s0 = si.m.x() * x0 + si.m.y() * ry;
      g.u0 = si.g.x() * x0 + si.g.y() * ry;
      row_sum = shortRowLanes(g, n, w);
    }
    else
    {
      // s = mᵀr = m_x·x + m_y·Y along the row (slope m_x·p per column); u = gᵀr likewise. u is linear in k, so the
      // pixels whose bracket is exactly 2 (6 < u < √A − 6) form one run [k_a, k_b): only the cross factor there.
      ErfRow e;
      e.s0 = si.m.x() * x0 + si.m.y() * ry;
      e.ds = si.m.x() * p;
      e.u0 = si.g.x() * x0 + si.g.y() * ry;
      e.du = si.g.x() * p;
      e.sqrt_a = si.sqrt_a;
      e.gauss_q = erf_q;
      int ka = n, kb = n;
      const double u_lo = kErfSaturated, u_hi = si.sqrt_a - kErfSaturated;
      if (u_lo < u_hi)
      {
        double k_lo = -INFINITY, k_hi = INFINITY;  // open interval of k with u_lo < u_k < u_hi
        if (e.du > 0.0)
        {
          k_lo = (u_lo - e.u0) / e.du;
          k_hi = (u_hi - e.u0) / e.du;
        }
        else if (e.du < 0.0)
        {
          k_lo = (u_hi - e.u0) / e.du;
          k_hi = (u_lo - e.u0) / e.du;
        }
        else if (!(e.u0 > u_lo && e.u0 < u_hi))
          k_hi = k_lo;
        const double first_k = std::max(0.0, std::floor(k_lo) + 1.0), end_k = std::min<double>(n, std::ceil(k_hi));
        if (first_k < end_k)
        {
          ka = static_cast<int>(first_k);
          kb = static_cast<int>(end_k);
        }
      }
      // In column order (each span's last block spills into the next span, which overwrites it).
      row_sum = erfRowLanes(e, 0, ka, false, w);
      row_sum += erfRowLanes(e, ka, kb, true, w);
      row_sum += erfRowLanes(e, kb, n, false, w);
    }
    StrokeWeights::Row r;
    r.row = static_cast<std::int64_t>(jr);
    r.col = static_cast<std::int64_t>(i_lo);
    r.n = n;
    r.offset = used;
    r.sum = row_sum;
    total += r.sum;
    out.rows.push_back(r);
    used += static_cast<std::size_t>(n);
  }
  out.total = total;
}

void StrokeDeposit::apply(TiledEnergyMap& map, const StrokeWeights& weights, double& outside_j)
{
  const double energy_j = weights.energy_j;
  if (weights.off_map)
  {
    outside_j += energy_j;
    return;
  }
  const double p = map.pixel();
  const Eigen::Vector2d& o = map.origin();
  const std::int64_t width = map.width(), height = map.height();
  const double total = weights.total;
  for (const StrokeWeights::Row& r : weights.rows)
    pixels_ += static_cast<std::uint64_t>(r.n);
  if (!(total > 0.0))
  {
    // No pixel centre in reach of the spot (pixels far larger than it): the pixel holding the midpoint takes it all.
    const Eigen::Vector2d& mid = weights.midpoint;
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
  for (const StrokeWeights::Row& r : weights.rows)
  {
    if (r.row < 0 || r.row >= height)
      continue;
    const std::int64_t klo = std::max<std::int64_t>(0, -r.col);
    const std::int64_t khi = std::min<std::int64_t>(r.n - 1, width - 1 - r.col);
    if (klo > khi)
      continue;
    const float* w = weights.weights.data() + r.offset;
    const int count = static_cast<int>(khi - klo + 1);
    map.addRow(r.row, r.col + klo, w + klo, scale, count);
    weight_in += count == r.n ? r.sum : energy_detail::sumRow(w + klo, count);
  }
  if (weight_in < total)
    outside_j += energy_j * ((total - weight_in) / total);
}
}  // namespace scanhead
