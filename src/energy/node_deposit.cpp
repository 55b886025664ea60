/// \file node_deposit.cpp
/// \brief Windows of trapezoid nodes drawn as sums of separable Gaussians.
#include "scanhead/energy/node_deposit.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <memory>
#include <vector>

#include "lane_math.hpp"
#include "row_kernels.hpp"

namespace scanhead
{
namespace
{
using energy_detail::F8;

/// \brief x in every lane (a broadcast: F8{x, …, x} is built lane by lane by GCC).
SCANHEAD_LANE_INLINE F8 splat(float x)
{
  return F8{} + x;
}

// First omitted outer product, of the footprint's peak: the whole remainder and the renormalisation come to ≤ ~2.5×
// that (test_trapezoid_deposit.cpp: ≤ 1.2e-4 of the peak up to 30° of incidence).
constexpr double kRankTolerance = 4.0e-5;

using energy_detail::firstCentre;
using energy_detail::lastCentre;

/// \brief ρ_m: the largest skew ρ = |q_xy|/√(q_xx q_yy) for which m outer products meet kRankTolerance, i.e. the
/// first omitted term ρ^m·(m/e)^m/m! ≤ tolerance (node_deposit.hpp).
const std::array<double, NodeDeposit::kMaxRank + 1>& rankBounds()
{
  static const std::array<double, NodeDeposit::kMaxRank + 1> bounds = [] {
    std::array<double, NodeDeposit::kMaxRank + 1> b{};
    for (int m = 1; m <= NodeDeposit::kMaxRank; ++m)
      b[static_cast<std::size_t>(m)] = std::pow(kRankTolerance * std::tgamma(m + 1.0) / std::pow(m / M_E, m), 1.0 / m);
    return b;
  }();
  return bounds;
}

/// \brief Where one window is drawn: its origin pixel, its rows of `stride` floats (blocks of 8 on a 32-byte grid)
/// and the span of columns each row received (relative to col_lo; lo > hi: none).
struct WindowGrid
{
  double p = 0.0;
  Eigen::Vector2d origin = Eigen::Vector2d::Zero();
  std::int64_t col_lo = 0, row_lo = 0;
  std::size_t stride = 0;
  float* window = nullptr;
  std::int32_t* span_lo = nullptr;
  std::int32_t* span_hi = nullptr;
  double truncation_radii = 0.0;
};

/// \brief One axis of a node: its pixels first … first + n − 1 and g[m·8·blocks + lead + k] = exp(−a·d_k²)·d_k^m
/// (d_k the offset of pixel first + k from the centre [m]), zeros before (lead < 8: the blocks then lie on the
/// window's grid of 8 columns) and after; sums[m] = Σ of them.
struct AxisLanes
{
  std::int64_t first = 0;
  int n = 0, lead = 0, blocks = 0;
  std::vector<float> g;
  double sums[NodeDeposit::kMaxRank];

  float* power(int m) { return g.data() + static_cast<std::size_t>(m) * 8 * static_cast<std::size_t>(blocks); }
};

/// \brief The pixels within \p radius of \p centre along one axis (n = 0: none; unreachable, R ≥ w ≥ the pixel).
SCANHEAD_LANE_INLINE void axisRange(AxisLanes& axis, double centre, double radius, double origin, double p)
{
  const double lo = firstCentre(centre - radius, origin, p), hi = lastCentre(centre + radius, origin, p);
  axis.first = static_cast<std::int64_t>(lo);
  axis.n = hi < lo ? 0 : static_cast<int>(hi - lo) + 1;
}

/// Blocks between two exact evaluations of an axis's Gaussian (bounds the recurrence's compounded rounding).
constexpr int kAnchorBlocks = 8;

/// \brief The Gaussian and its powers on the axis's pixels. Every kAnchorBlocks-th block by Cephes' expf of exponents
/// formed in float (relative error ~1e-7 of an exponent ≤ 13: ≤ 1.5e-6 of a weight); the blocks between by the
/// second-order recurrence of a quadratic exponent: with D_k = a·p²·((d_k + 8)² − d_k²), e_{k+8} = e_k·e^{−D_k} and
/// e^{−D_{k+8}} = e^{−D_k}·e^{−128·a·p²} (≤ 7 products compound: ~1e-6; at w = 35 µm a node spans 5 blocks).
template <int R>
SCANHEAD_LANE_INLINE void axisGaussianOfRank(AxisLanes& axis, double centre, double origin, double p, double a,
                                             int any_rank, int lead)
{
  const int rank = R > 0 ? R : any_rank;
  axis.lead = lead;
  axis.blocks = (lead + axis.n + 7) / 8;
  const std::size_t size = static_cast<std::size_t>(rank) * 8 * static_cast<std::size_t>(axis.blocks);
  if (axis.g.size() < size)
    axis.g.resize(size);
  const double d0 = (origin + (static_cast<double>(axis.first) + 0.5) * p - centre) / p - lead;  // pixels
  const float ap2 = static_cast<float>(a * p * p);
  const F8 q = energy_detail::expNeg(splat(128.0f * ap2));
  F8 e = splat(0.0f), ratio = e, dm = e;  // set at block 0 (an anchor)
  F8 sums[R > 0 ? R : NodeDeposit::kMaxRank];
  for (int m = 0; m < rank; ++m)
    sums[m] = splat(0.0f);
  for (int b = 0; b < axis.blocks; ++b)
  {
    if (b % kAnchorBlocks == 0)
    {
      const F8 d = splat(static_cast<float>(d0 + 8.0 * b)) + energy_detail::laneIndex();
      e = energy_detail::expNeg(splat(ap2) * d * d);
      ratio = energy_detail::expNeg(splat(ap2) * (splat(16.0f) * d + splat(64.0f)));
      dm = d * splat(static_cast<float>(p));  // metres
    }
    const F8 column = energy_detail::laneIndex() + splat(static_cast<float>(8 * b - lead));
    const auto live = column >= splat(0.0f) && column < splat(static_cast<float>(axis.n));
    F8 v = live ? e : splat(0.0f);
    for (int m = 0; m < rank; ++m)
    {
      std::memcpy(axis.power(m) + 8 * b, &v, sizeof v);
      sums[m] += v;
      v *= dm;
    }
    e *= ratio;
    ratio *= q;
    dm += splat(static_cast<float>(8.0 * p));
  }
  for (int m = 0; m < rank; ++m)
    axis.sums[m] = energy_detail::laneSum(sums[m]);
}

/// \brief axisGaussianOfRank with the common ranks 1–3 known when compiled (the powers' loop unrolled, their sums in
/// registers; the same operations).
SCANHEAD_LANE_INLINE void axisGaussian(AxisLanes& axis, double centre, double origin, double p, double a, int rank,
                                       int lead)
{
  switch (rank)
  {
    case 1:
      return axisGaussianOfRank<1>(axis, centre, origin, p, a, 1, lead);
    case 2:
      return axisGaussianOfRank<2>(axis, centre, origin, p, a, 2, lead);
    case 3:
      return axisGaussianOfRank<3>(axis, centre, origin, p, a, 3, lead);
    default:
      return axisGaussianOfRank<0>(axis, centre, origin, p, a, rank, lead);
  }
}

/// \brief Scratch of a window's draw (kept per thread: it grows to the largest node drawn).
struct NodeScratch
{
  AxisLanes x, y;
  std::vector<float> a;                        ///< the rows' factors a_m[j], like y.g
  std::vector<std::int32_t> span_lo, span_hi;  ///< the window's rows' spans (WindowGrid)
  std::vector<double> sums;                    ///< their weights' sums
  std::vector<float> window;                   ///< the window drawn (hot in cache; its rows' spans are copied out)
};

/// \brief rows[j][0 … 8·blocks) += Σ_m a[m·a_stride + j]·g[m·8·blocks + …]: the row's factors broadcast once, the
/// products summed in m order, then added (the same bits whatever R and B, and on every clone: no FMA). R > 0: the rank
/// known when compiled (the factors in registers); 0: \p any_rank. For the 5 or 6 blocks a row a node's 35 columns take
/// at w = 35 µm, 5 µm pixels, the block count \p B is known too: the row's loop unrolled, the g vectors kept in
/// registers across the rows.
template <int R, int B = 0>
SCANHEAD_LANE_INLINE void addOuterProductsOfRank(float* __restrict rows, std::size_t stride, int n_rows, int any_blocks,
                                                 int any_rank, const float* __restrict a, std::size_t a_stride,
                                                 const float* __restrict g)
{
  const int rank = R > 0 ? R : any_rank;
  const int blocks = B > 0 ? B : any_blocks;
  if (B == 0 && (blocks == 5 || blocks == 6))
  {
    if (blocks == 5)
      return addOuterProductsOfRank<R, 5>(rows, stride, n_rows, 5, rank, a, a_stride, g);
    return addOuterProductsOfRank<R, 6>(rows, stride, n_rows, 6, rank, a, a_stride, g);
  }
  const std::size_t g_stride = 8 * static_cast<std::size_t>(blocks);
  for (int j = 0; j < n_rows; ++j)
  {
    float* __restrict row = rows + static_cast<std::size_t>(j) * stride;
    F8 factor[R > 0 ? R : NodeDeposit::kMaxRank];
    for (int m = 0; m < rank; ++m)
      factor[m] = splat(a[static_cast<std::size_t>(m) * a_stride + static_cast<std::size_t>(j)]);
    for (int b = 0; b < blocks; ++b)
    {
      F8 gb, v;
      std::memcpy(&gb, g + 8 * b, sizeof gb);
      F8 sum = factor[0] * gb;
      for (int m = 1; m < rank; ++m)
      {
        std::memcpy(&gb, g + static_cast<std::size_t>(m) * g_stride + 8 * b, sizeof gb);
        sum += factor[m] * gb;
      }
      std::memcpy(&v, row + 8 * b, sizeof v);
      v += sum;
      std::memcpy(row + 8 * b, &v, sizeof v);
    }
  }
}

/// \brief addOuterProductsOfRank with ranks 1–3 (98 % of a layer's nodes: 2 %, 71 % and 26 % on the THESIS layer)
/// known when compiled.
SCANHEAD_LANE_INLINE void addOuterProducts(float* __restrict rows, std::size_t stride, int n_rows, int blocks, int rank,
                                           const float* __restrict a, std::size_t a_stride, const float* __restrict g)
{
  switch (rank)
  {
    case 1:
      return addOuterProductsOfRank<1>(rows, stride, n_rows, blocks, 1, a, a_stride, g);
    case 2:
      return addOuterProductsOfRank<2>(rows, stride, n_rows, blocks, 2, a, a_stride, g);
    case 3:
      return addOuterProductsOfRank<3>(rows, stride, n_rows, blocks, 3, a, a_stride, g);
    default:
      return addOuterProductsOfRank<0>(rows, stride, n_rows, blocks, rank, a, a_stride, g);
  }
}

/// \brief Draws nodes[0 … count) on the window: per node the columns' and rows' Gaussians, normalised to its energy,
/// then rows[j] += Σ_m a_m[j]·g_m 8 columns at a time (the products summed in m order, then added: the same bits on
/// every clone, no FMA); every node reads and writes the same aligned blocks, so each load is served by the previous
/// node's store and none splits a cache line.
__attribute__((target_clones("avx2", "default"))) void drawNodes(const WindowGrid& w, const QuadratureNode* nodes,
                                                                 std::size_t count, NodeScratch& s)
{
  for (std::size_t k = 0; k < count; ++k)
  {
    const QuadratureNode& nd = nodes[k];
    const SpotFootprint& fp = nd.footprint;
    const double radius = w.truncation_radii * fp.major_radius_m;
    axisRange(s.x, nd.centre.x(), radius, w.origin.x(), w.p);
    axisRange(s.y, nd.centre.y(), radius, w.origin.y(), w.p);
    if (s.x.n == 0 || s.y.n == 0)
      continue;
    const int rank = NodeDeposit::rank(fp);
    const std::int64_t row0 = s.y.first - w.row_lo, col0 = s.x.first - w.col_lo;
    axisGaussian(s.x, nd.centre.x(), w.origin.x(), w.p, fp.qxx, rank, static_cast<int>(col0 % 8));
    axisGaussian(s.y, nd.centre.y(), w.origin.y(), w.p, fp.qyy, rank, 0);
    // c_m = (−2q_xy)^m/m!; the node's Σ_m c_m·(Σ_x g_m)(Σ_y g_m) normalised to e_j.
    double c[NodeDeposit::kMaxRank], total = 0.0, cm = 1.0;
    for (int m = 0; m < rank; ++m)
    {
      c[m] = cm;
      total += cm * s.x.sums[m] * s.y.sums[m];
      cm *= -2.0 * fp.qxy / static_cast<double>(m + 1);
    }
    if (!(total > 0.0))
      continue;  // unreachable (the central term dominates); apply() spreads the window's energy anyway
    const std::size_t a_stride = 8 * static_cast<std::size_t>(s.y.blocks);
    if (s.a.size() < static_cast<std::size_t>(rank) * a_stride)
      s.a.resize(static_cast<std::size_t>(rank) * a_stride);
    for (int m = 0; m < rank; ++m)
    {
      const F8 scale = splat(static_cast<float>(nd.energy_j / total * c[m]));
      for (int b = 0; b < s.y.blocks; ++b)
      {
        F8 v;
        std::memcpy(&v, s.y.power(m) + 8 * b, sizeof v);
        v *= scale;
        std::memcpy(s.a.data() + static_cast<std::size_t>(m) * a_stride + 8 * b, &v, sizeof v);
      }
    }
    float* rows = w.window + static_cast<std::size_t>(row0) * w.stride + static_cast<std::size_t>(col0 / 8 * 8);
    addOuterProducts(rows, w.stride, s.y.n, s.x.blocks, rank, s.a.data(), a_stride, s.x.g.data());
    const std::int32_t lo = static_cast<std::int32_t>(col0), hi = static_cast<std::int32_t>(col0 + s.x.n - 1);
    // 8 rows at a time (the span arrays have room for a last block past the window's rows).
    using energy_detail::I8;
    const I8 lo8 = I8{} + lo, hi8 = I8{} + hi;
    std::int32_t* span_lo = w.span_lo + row0;
    std::int32_t* span_hi = w.span_hi + row0;
    for (int j = 0; j < s.y.n; j += 8)
    {
      I8 l, h;
      std::memcpy(&l, span_lo + j, sizeof l);
      std::memcpy(&h, span_hi + j, sizeof h);
      const I8 mask = energy_detail::laneIndexInt() < (I8{} + (s.y.n - j));
      l = mask & (lo8 < l) ? lo8 : l;
      h = mask & (hi8 > h) ? hi8 : h;
      std::memcpy(span_lo + j, &l, sizeof l);
      std::memcpy(span_hi + j, &h, sizeof h);
    }
  }
}

/// \brief sums[j] = Σ of row j's weights over its span (8 float lanes, then in double: a fixed order).
__attribute__((target_clones("avx2", "default"))) void spanSums(const float* window, std::size_t stride,
                                                                std::size_t rows, const std::int32_t* span_lo,
                                                                const std::int32_t* span_hi, double* sums)
{
  for (std::size_t j = 0; j < rows; ++j)
  {
    sums[j] = 0.0;
    if (span_lo[j] > span_hi[j])
      continue;
    const float* x = window + j * stride + static_cast<std::size_t>(span_lo[j]);
    const int n = span_hi[j] - span_lo[j] + 1;
    F8 lanes = splat(0.0f);
    int k = 0;
    for (; k + 8 <= n; k += 8)
    {
      F8 v;
      std::memcpy(&v, x + k, sizeof v);
      lanes += v;
    }
    if (k < n)
    {
      F8 v;
      std::memcpy(&v, x + k, sizeof v);  // within the row's stride (room for a block past the window)
      energy_detail::accumulate(lanes, v, n - k);
    }
    sums[j] = energy_detail::laneSum(lanes);
  }
}
}  // namespace

NodeDeposit::NodeDeposit(const EnergyConfig& config)
  : config_(config)
{
}

int NodeDeposit::rank(const SpotFootprint& fp)
{
  const double rho = fp.qxy == 0.0 ? 0.0 : std::abs(fp.qxy) / std::sqrt(fp.qxx * fp.qyy);
  const auto& bounds = rankBounds();
  int m = 1;
  while (m < kMaxRank && rho > bounds[static_cast<std::size_t>(m)])
    ++m;
  return m;
}

bool NodeDeposit::joins(const OpenWindow& window, const QuadratureNode& node, double pixel_m) const
{
  if (window.count >= kWindowNodes || window.alone ||
      config_.truncation_radii * node.footprint.major_radius_m > kMaxWindowRadiusPixels * pixel_m)
    return false;
  // The box of the centres at most kWindowSpanPixels or one footprint wide (fine maps: the window's rows then hold
  // about as many pixels as one node's).
  const double span =
      std::max(kWindowSpanPixels * pixel_m, 2.0 * config_.truncation_radii * node.footprint.major_radius_m);
  const Eigen::Vector2d lo = window.lo.cwiseMin(node.centre), hi = window.hi.cwiseMax(node.centre);
  return hi.x() - lo.x() <= span && hi.y() - lo.y() <= span;
}

void NodeDeposit::add(OpenWindow& window, const QuadratureNode& node, double pixel_m) const
{
  if (window.count == 0)
  {
    window.lo = window.hi = node.centre;
    window.alone = config_.truncation_radii * node.footprint.major_radius_m > kMaxWindowRadiusPixels * pixel_m;
  }
  else
  {
    window.lo = window.lo.cwiseMin(node.centre);
    window.hi = window.hi.cwiseMax(node.centre);
  }
  window.major_radius_m = std::max(window.major_radius_m, node.footprint.major_radius_m);
  ++window.count;
}

void NodeDeposit::weigh(const TiledEnergyMap& map, const QuadratureNode* nodes, std::size_t count,
                        StrokeWeights& out) const
{
  out.rows.clear();
  out.total = 0.0;
  out.off_map = false;
  out.energy_j = 0.0;
  const double p = map.pixel();
  const Eigen::Vector2d& o = map.origin();
  const std::int64_t width = map.width(), height = map.height();

  // The rectangle of pixel centres that holds every node's square.
  double col_lo = INFINITY, col_hi = -INFINITY, row_lo = INFINITY, row_hi = -INFINITY;
  Eigen::Vector2d weighted = Eigen::Vector2d::Zero();
  for (std::size_t k = 0; k < count; ++k)
  {
    const QuadratureNode& nd = nodes[k];
    const double radius = config_.truncation_radii * nd.footprint.major_radius_m;
    col_lo = std::min(col_lo, firstCentre(nd.centre.x() - radius, o.x(), p));
    col_hi = std::max(col_hi, lastCentre(nd.centre.x() + radius, o.x(), p));
    row_lo = std::min(row_lo, firstCentre(nd.centre.y() - radius, o.y(), p));
    row_hi = std::max(row_hi, lastCentre(nd.centre.y() + radius, o.y(), p));
    out.energy_j += nd.energy_j;
    weighted += nd.energy_j * nd.centre;
  }
  out.midpoint = weighted / out.energy_j;
  if (col_hi < col_lo || row_hi < row_lo)
    return;  // no pixel centre in reach: apply() puts the energy in the midpoint's pixel
  if (row_hi < 0.0 || row_lo > static_cast<double>(height - 1) || col_hi < 0.0 ||
      col_lo > static_cast<double>(width - 1))
  {
    out.off_map = true;
    return;
  }
  // Rows of whole blocks of 8 on a 32-byte grid, with room for a node's last block.
  const std::size_t nx = static_cast<std::size_t>(col_hi - col_lo) + 1;
  const std::size_t ny = static_cast<std::size_t>(row_hi - row_lo) + 1;
  WindowGrid grid;
  grid.p = p;
  grid.origin = o;
  grid.col_lo = static_cast<std::int64_t>(col_lo);
  grid.row_lo = static_cast<std::int64_t>(row_lo);
  grid.stride = (nx + 7) / 8 * 8 + 8;
  grid.truncation_radii = config_.truncation_radii;
  // Drawn on the thread's scratch window (it stays in cache from one window to the next), then only the rows' spans
  // are copied to out.weights: a diagonal window's box is ~3 times the band its nodes reach.
  thread_local std::unique_ptr<NodeScratch> scratch;
  if (!scratch)
    scratch = std::make_unique<NodeScratch>();
  std::vector<float>& window = scratch->window;
  const std::size_t window_floats = grid.stride * ny + 8;
  if (window.size() < window_floats)
    window.resize(window_floats);
  std::memset(window.data(), 0, window_floats * sizeof(float));  // (assign's loop stores 16 bytes at a time)
  const std::size_t base = (32 - reinterpret_cast<std::uintptr_t>(window.data()) % 32) % 32 / sizeof(float);
  grid.window = window.data() + base;
  std::vector<std::int32_t>&span_lo = scratch->span_lo, &span_hi = scratch->span_hi;
  span_lo.assign(ny + 8, INT32_MAX);
  span_hi.assign(ny + 8, INT32_MIN);
  grid.span_lo = span_lo.data();
  grid.span_hi = span_hi.data();
  drawNodes(grid, nodes, count, *scratch);

  // One row a map row, trimmed to the columns some node reached.
  std::vector<double>& sums = scratch->sums;
  sums.assign(ny, 0.0);
  spanSums(grid.window, grid.stride, ny, span_lo.data(), span_hi.data(), sums.data());
  std::size_t kept = 0;
  for (std::size_t j = 0; j < ny; ++j)
    if (span_lo[j] <= span_hi[j])
      kept += static_cast<std::size_t>(span_hi[j] - span_lo[j] + 1);
  if (out.weights.size() < kept)
    out.weights.resize(kept);
  double total = 0.0;
  std::size_t offset = 0;
  for (std::size_t j = 0; j < ny; ++j)
  {
    if (span_lo[j] > span_hi[j])
      continue;
    StrokeWeights::Row r;
    r.row = grid.row_lo + static_cast<std::int64_t>(j);
    r.col = grid.col_lo + span_lo[j];
    r.n = span_hi[j] - span_lo[j] + 1;
    r.offset = offset;
    r.sum = sums[j];
    std::memcpy(out.weights.data() + offset, grid.window + j * grid.stride + static_cast<std::size_t>(span_lo[j]),
                static_cast<std::size_t>(r.n) * sizeof(float));
    offset += static_cast<std::size_t>(r.n);
    total += r.sum;
    out.rows.push_back(r);
  }
  out.total = total;
}
}  // namespace scanhead
