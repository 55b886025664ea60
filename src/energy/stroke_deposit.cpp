/// \file stroke_deposit.cpp
/// \brief The closed-form deposit of a straight constant-velocity stroke, row by row.
#include "scanhead/energy/stroke_deposit.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "gauss_legendre.hpp"
#include "lane_math.hpp"
#include "row_kernels.hpp"
#include "scanhead/energy/segment_integral.hpp"

namespace scanhead
{
namespace
{
constexpr double kErfSaturated = 6.0;  // erf(±6) = ±1 in double (erfc 6 = 2.2e-17 < half an ulp of 1)

// √A up to this: the erf difference by Gauss–Legendre quadrature over the stroke's bounding rectangle
// (quadratureRectangle), beyond by the erf form on the capsule's rows (erfRowLanes). See bracketRuleNodes.
constexpr double kQuadratureStroke = 6.0;

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
  /// \brief Starts the row from a known first block: \p e_first = e^{−Q} at its lanes, \p r_first = e^{−D} (the row's
  /// first anchor then costs no exponential; kAnchorBlocks blocks on, the row anchors itself as usual).
  SCANHEAD_LANE_INLINE void start(energy_detail::F8 e_first, energy_detail::F8 r_first)
  {
    e = e_first;
    r = r_first;
    left = kAnchorBlocks;
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

/// \brief A stroke of √A ≤ kQuadratureStroke on the rectangle of pixels that bounds its capsule, for
/// quadratureRectangle. With the Gauss–Legendre nodes c_i = √A(τ_i − ½) and the stroke's coordinates centred on its
/// midpoint (s across, u' = u − √A/2 along, both linear in the pixel's row and column),
/// W = Σ_i a_i·e^{−s² − (u' − c_i)²} = e^{−s² − u'²}·Σ_i [a_i e^{2c_i u'_0 − c_i²}]·e^{2c_i du·k}, a_i = (2/√π)√A·w_i,
/// u'_0 at the row's first column: a Gaussian (GaussianSteps) times a sum of geometric sequences along each row.
struct QuadratureStroke
{
  static constexpr int kMaxNodes = 14;
  int nodes = 4;
  // The first row's first column, and the steps per column and per row:
  double s0 = 0.0, u0 = 0.0, ds = 0.0, du = 0.0, ds_row = 0.0, du_row = 0.0;  ///< s and u'
  double along0 = 0.0, across0 = 0.0;  ///< the pixel centre's offset from the stroke's start, along and across it [px]
  /// The stroke's unit direction (tx, ty): a pixel's offset (X, Y) from the start [px] lies along = tx·X + ty·Y and
  /// across = −ty·X + tx·Y, so one column adds (tx, −ty) to them and one row (ty, tx).
  double tx = 1.0, ty = 0.0;
  float length_px = 0.0f, radius2_px = 0.0f;  ///< the capsule: segment length and truncation radius² [px, px²]
  double factor[kMaxNodes] = {};              ///< a_i e^{2c_i u'_0 − c_i²} on the first row
  double factor_row[kMaxNodes] = {};          ///< e^{2c_i du_row}: one row further
  float lanes[kMaxNodes][8] = {};             ///< e^{2c_i du·l}, l = 0..7
  float advance[kMaxNodes] = {};              ///< e^{16 c_i du}: one block further
  float gauss_q = 0.0f;                       ///< gaussianRatio(ds, du)
};

/// Rows between two exact evaluations of the Gaussian's first block (bounds the growth of the products' rounding).
constexpr int kAnchorRows = 8;

/// \brief e^{−x} at 8 lanes from exponents in double, split into float hi + lo: e^{−hi}·(1 − lo) (|lo| ≤ 2e-6, so the
/// first order is exact to 2e-12). Rounding the argument itself to float would cost |x|·6e-8 relative, 3e-6 at the
/// |x| ≈ 50 a stroke's rectangle reaches where the nodes' factors make the product large; this keeps expNeg's 2 ulp.
SCANHEAD_LANE_INLINE energy_detail::F8 expNegSplit(const double (&x)[8])
{
  using namespace energy_detail;
  F8 hi, lo;
  for (int l = 0; l < 8; ++l)
  {
    hi[l] = static_cast<float>(x[l]);
    lo[l] = static_cast<float>(x[l] - static_cast<double>(hi[l]));
  }
  return expNeg(hi) * (splat(1.0f) - lo);
}

/// \brief w[k·n + j] for the rows k < rows and columns j < n (each row rounded up to a multiple of 8 from its start:
/// w has room for the last row's excess), the rows' sums in \p row_sums. \tparam N nodes.
///
/// Along a row: the Gaussian by GaussianSteps, each node's factor a product (relative error ~6e-8 a block), 0 outside
/// the capsule (pixel centres within R of the segment: the truncation of the other methods). From row to row:
/// Q(k + 1, l) − Q(k, l) = 2(s_k Δs + u'_k Δu) + Δs² + Δu² + 2l(ds Δs + du Δu) is linear in k, so the first block's
/// e^{−Q}, GaussianSteps' ratio e^{−D} and the nodes' factors follow by products too (V ← V·c_V), anchored every
/// kAnchorRows rows by exact exponentials (exponents split hi/lo: expNegSplit), error ≤ ~2·kAnchorRows·6e-8 relative
/// to the value, ~1e-6 of the stroke's peak (test_stroke_deposit.cpp). A row longer than kAnchorBlocks blocks (only the
/// longest strokes' last pixel) re-anchors as GaussianSteps does, its exponent rounded to float (~3e-6 relative).
template <int N>
SCANHEAD_LANE_INLINE void quadratureRows(const QuadratureStroke& q, int rows, int n, float* w, double* row_sums)
{
  using namespace energy_detail;
  const F8 lane = laneIndex();
  const double a = q.ds * q.ds + q.du * q.du, a_row = q.ds_row * q.ds_row + q.du_row * q.du_row;
  const double cross = q.ds * q.ds_row + q.du * q.du_row;
  const F8 c_v = splat(static_cast<float>(std::exp(-2.0 * a_row)));
  const F8 c_r = splat(static_cast<float>(std::exp(-16.0 * cross)));
  const F8 along_step = splat(static_cast<float>(q.tx)), across_step = splat(static_cast<float>(-q.ty));
  const F8 along_block = splat(static_cast<float>(8.0 * q.tx));
  const F8 across_block = splat(static_cast<float>(-8.0 * q.ty));
  const F8 zero = splat(0.0f), length = splat(q.length_px), radius2 = splat(q.radius2_px);
  F8 gauss_e = zero, gauss_r = zero, gauss_v = zero;
  double factor[N];
  for (int i = 0; i < N; ++i)
    factor[i] = q.factor[i];
  for (int k = 0; k < rows; ++k)
  {
    const double s0 = q.s0 + k * q.ds_row, u0 = q.u0 + k * q.du_row;
    if (k % kAnchorRows == 0)
    {
      // Q, GaussianSteps' D = Q(l + 8) − Q(l) and the row step ΔQ at the lanes, in double.
      double q_lanes[8], d_lanes[8], v_lanes[8];
      for (int l = 0; l < 8; ++l)
      {
        const double sl = s0 + l * q.ds, ul = u0 + l * q.du;
        q_lanes[l] = sl * sl + ul * ul;
        d_lanes[l] = 16.0 * (sl * q.ds + ul * q.du) + 64.0 * a;
        v_lanes[l] = 2.0 * (sl * q.ds_row + ul * q.du_row) + a_row;
      }
      gauss_e = expNegSplit(q_lanes);
      gauss_r = expNegSplit(d_lanes);
      gauss_v = expNegSplit(v_lanes);
    }
    else
    {
      gauss_e = gauss_e * gauss_v;
      gauss_v = gauss_v * c_v;
      gauss_r = gauss_r * c_r;
    }
    F8 node[N];
#pragma GCC unroll 14
    for (int i = 0; i < N; ++i)
    {
      F8 lanes;
      std::memcpy(&lanes, q.lanes[i], sizeof lanes);
      node[i] = splat(static_cast<float>(factor[i])) * lanes;
      factor[i] *= q.factor_row[i];  // the next row's (double)
    }
    // The capsule's coordinates at the lanes, in pixels (float, stepped a block at a time: ≤ ~1e-5 px off at a row's
    // end, immaterial to the truncation).
    F8 along = splat(static_cast<float>(q.along0 + k * q.ty)) + along_step * lane;
    F8 across = splat(static_cast<float>(q.across0 + k * q.tx)) + across_step * lane;
    GaussianSteps gaussian(s0, q.ds, u0, q.du, q.gauss_q);
    gaussian.start(gauss_e, gauss_r);
    float* row = w + static_cast<std::size_t>(k) * static_cast<std::size_t>(n);
    F8 total = zero;
    for (int k0 = 0; k0 < n; k0 += 8)
    {
      F8 sum = node[0];
#pragma GCC unroll 14
      for (int i = 1; i < N; ++i)
        sum += node[i];
      F8 value = gaussian.next(k0, n) * sum;
      const F8 beyond = along < zero ? along : (along > length ? along - length : zero);
      value = across * across + beyond * beyond <= radius2 ? value : zero;
      along += along_block;
      across += across_block;
      std::memcpy(row + k0, &value, sizeof value);
      accumulate(total, value, n - k0);
#pragma GCC unroll 14
      for (int i = 0; i < N; ++i)
        node[i] *= splat(q.advance[i]);
    }
    row_sums[k] = laneSum(total);
  }
}

/// \brief quadratureRows for the stroke's node count (each count unrolled in each clone).
__attribute__((target_clones("avx2", "default"))) void quadratureRectangle(const QuadratureStroke& q, int rows, int n,
                                                                           float* w, double* row_sums)
{
  switch (q.nodes)
  {
    case 4:
      return quadratureRows<4>(q, rows, n, w, row_sums);
    case 5:
      return quadratureRows<5>(q, rows, n, w, row_sums);
    case 6:
      return quadratureRows<6>(q, rows, n, w, row_sums);
    case 7:
      return quadratureRows<7>(q, rows, n, w, row_sums);
    case 8:
      return quadratureRows<8>(q, rows, n, w, row_sums);
    case 9:
      return quadratureRows<9>(q, rows, n, w, row_sums);
    case 10:
      return quadratureRows<10>(q, rows, n, w, row_sums);
    case 11:
      return quadratureRows<11>(q, rows, n, w, row_sums);
    case 12:
      return quadratureRows<12>(q, rows, n, w, row_sums);
    case 13:
      return quadratureRows<13>(q, rows, n, w, row_sums);
    default:
      return quadratureRows<14>(q, rows, n, w, row_sums);
  }
}

/// \brief The weights of a stroke of √A ≤ kQuadratureStroke over the pixel rectangle [row_lo, row_hi] × [col_lo,
/// col_hi] that bounds its capsule (quadratureRectangle: every row the same columns, so no chord to find and no
/// exponential a row). Pixels outside the capsule weigh 0 and are trimmed from the rows; the rectangle holds 15 % (a
/// stroke along an axis) to 35 % (diagonal) more pixels than the capsule, each ~2× cheaper than the erf form's.
void weighRectangle(const SegmentIntegral& si, const Stroke& stroke, const TiledEnergyMap& map, double radius,
                    double length, const Eigen::Vector2d& t, double row_lo, double row_hi, double col_lo, double col_hi,
                    StrokeWeights& out)
{
  const double p = map.pixel(), inv_p = 1.0 / p;
  const Eigen::Vector2d& o = map.origin();
  const Eigen::Vector2d& c0 = stroke.start;
  QuadratureStroke q;
  q.nodes = energy_detail::bracketRuleNodes(si.sqrt_a);
  // The first pixel's offset from the start.
  const double x0 = o.x() + (col_lo + 0.5) * p - c0.x(), y0 = o.y() + (row_lo + 0.5) * p - c0.y();
  const double half = 0.5 * si.sqrt_a;
  q.s0 = si.m.x() * x0 + si.m.y() * y0;
  q.u0 = si.g.x() * x0 + si.g.y() * y0 - half;
  q.ds = si.m.x() * p;
  q.du = si.g.x() * p;
  q.ds_row = si.m.y() * p;
  q.du_row = si.g.y() * p;
  q.along0 = (t.x() * x0 + t.y() * y0) * inv_p;
  q.across0 = (-t.y() * x0 + t.x() * y0) * inv_p;
  q.tx = t.x();
  q.ty = t.y();
  q.length_px = static_cast<float>(length * inv_p);
  q.radius2_px = static_cast<float>((radius * inv_p) * (radius * inv_p));
  q.gauss_q = gaussianRatio(q.ds, q.du);
  const energy_detail::GaussLegendreRule& rule = energy_detail::gaussLegendreRule(q.nodes);
  for (int i = 0; i < q.nodes; ++i)
  {
    const double c = si.sqrt_a * (rule.node[i] - 0.5);
    // e^{2c du·l} by powers of e^{2c du} (double), each rounded once.
    const double ratio = std::exp(2.0 * c * q.du);
    double power = 1.0;
    for (int l = 0; l < 8; ++l)
    {
      q.lanes[i][l] = static_cast<float>(power);
      power *= ratio;
    }
    q.advance[i] = static_cast<float>(power);
    q.factor[i] = 2.0 / std::sqrt(M_PI) * si.sqrt_a * rule.weight[i] * std::exp(c * (2.0 * q.u0 - c));
    q.factor_row[i] = std::exp(2.0 * c * q.du_row);
  }
  const int n = static_cast<int>(col_hi - col_lo) + 1;
  const int rows = static_cast<int>(row_hi - row_lo) + 1;
  const std::size_t size = static_cast<std::size_t>(rows) * static_cast<std::size_t>(n) + 8;
  std::vector<float>& weights = out.weights;
  if (weights.size() < size)
    weights.resize(std::max(2 * weights.size(), size));
  thread_local std::vector<double> row_sums;  // weigh() runs on several threads at once: a scratch each
  row_sums.resize(static_cast<std::size_t>(rows));
  quadratureRectangle(q, rows, n, weights.data(), row_sums.data());
  // Each row trimmed to the capsule (its zeros at both ends): the map adds, and the tiles it touches, are the
  // capsule's.
  double total = 0.0;
  for (int k = 0; k < rows; ++k)
  {
    const float* w = weights.data() + static_cast<std::size_t>(k) * static_cast<std::size_t>(n);
    int begin = 0, end = n;
    while (begin < end && w[begin] == 0.0f)
      ++begin;
    while (end > begin && w[end - 1] == 0.0f)
      --end;
    if (begin == end)
      continue;
    StrokeWeights::Row r;
    r.row = static_cast<std::int64_t>(row_lo) + k;
    r.col = static_cast<std::int64_t>(col_lo) + begin;
    r.n = end - begin;
    r.offset = static_cast<std::size_t>(k) * static_cast<std::size_t>(n) + static_cast<std::size_t>(begin);
    r.sum = row_sums[static_cast<std::size_t>(k)];
    total += r.sum;
    out.rows.push_back(r);
  }
  out.total = total;
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

  auto first = [p](double a, double origin) { return energy_detail::firstCentre(a, origin, p); };
  auto last = [p](double b, double origin) { return energy_detail::lastCentre(b, origin, p); };
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
  if (!si.stationary && si.sqrt_a <= kQuadratureStroke)
  {
    weighRectangle(si, stroke, map, radius, length, t, row_lo, row_hi, col_lo, col_hi, out);
    return;
  }
  const Eigen::Vector2d nrm(-t.y(), t.x());
  // Per-stroke constants of the row recurrences (curvatures along a row, in columns).
  const double alpha_stationary = si.qxx * p * p;
  const float erf_q = si.stationary ? 0.0f : gaussianRatio(si.m.x() * p, 0.0);
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
