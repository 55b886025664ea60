/// \file optical_model.cpp
/// \brief Ray trace (with forward-mode Jacobian) and Newton inverse of the two-mirror head.
#include "scanhead/optics/optical_model.hpp"

#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <sstream>
#include <vector>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "scanhead/common/errors.hpp"

namespace scanhead
{
namespace detail
{
template <typename T>
struct V3
{
  T x, y, z;
};

/// The constant surfaces of the trace, as plain doubles.
struct TraceSurfaces
{
  V3<double> source_point, source_direction;
  V3<double> mx_n_c, mx_n_s, mx_n_0, mx_p_c, mx_p_s, mx_p_0;
  V3<double> my_n_c, my_n_s, my_n_0, my_p_c, my_p_s, my_p_0;
  V3<double> w1_point, w1_normal, w2_point, w2_normal;
  V3<double> plane_point, plane_normal;
  V3<double> rt0, rt1, rt2;  ///< rows of the base -> work-plane rotation
  double thickness, eta;
};
}  // namespace detail

namespace
{
using Vec3 = Eigen::Vector3d;
using Mat32 = Eigen::Matrix<double, 3, 2>;

/// The trace is a chain of small Eigen expressions: inlining all of it into the two entry points
/// saves about a third of the cost (measured with GCC -O2: trace 97 -> 63 ns, trace with
/// Jacobian 172 -> 127 ns; forcing inline on the helpers instead made the Jacobian slower).
/// The error paths stay out of line (cold) so that flattening does not inline their string code.
#if defined(__GNUC__)
#define SCANHEAD_FLATTEN __attribute__((flatten))
#define SCANHEAD_COLD __attribute__((cold, noinline))
#else
#define SCANHEAD_FLATTEN
#define SCANHEAD_COLD
#endif

/// |d.n| below this: the ray is taken as parallel to the surface (no intersection).
constexpr double kMinCosine = 1e-9;

/// Ray state: point p, unit direction d and, when tracked, their derivatives w.r.t. (θx, θy).
struct RayState
{
  Vec3 p;
  Vec3 d;
  Mat32 dp;
  Mat32 dd;
};

/// The Taylor polynomials of sinCos() on a number type T (double, or the block trace's Lanes, Lanes2):
/// the same operations lane by lane. Coefficients (-1)^k / (2k+1)! and (-1)^k / (2k)!, folded at compile time.
template <typename T>
inline __attribute__((always_inline)) void sinCosPolynomial(const T& x, T& s, T& c)
{
  const T z = x * x;
  s = x + x * z *
              (-1.0 / 6 +
               z * (1.0 / 120 +
                    z * (-1.0 / 5040 +
                         z * (1.0 / 362880 + z * (-1.0 / 39916800 +
                                                  z * (1.0 / 6227020800.0 + z * (-1.0 / 1307674368000.0 +
                                                                                 z * (1.0 / 355687428096000.0))))))));
  c = 1.0 + z * (-0.5 + z * (1.0 / 24 +
                             z * (-1.0 / 720 + z * (1.0 / 40320 +
                                                    z * (-1.0 / 3628800 + z * (1.0 / 479001600.0 +
                                                                               z * (-1.0 / 87178291200.0 +
                                                                                    z * (1.0 / 20922789888000.0))))))));
}

/// sin and cos of \p x: Taylor polynomials (Horner in x^2) for |x| <= 0.25 rad, whose first
/// neglected terms (x^19/19!, x^18/18!) are < 1e-26, far below one ulp; libm elsewhere.
/// Galvo angles stay within ±0.1745 rad, so the fast path is the one taken.
inline void sinCos(double x, double& s, double& c)
{
  if (std::abs(x) > 0.25)
  {
    s = std::sin(x);
    c = std::cos(x);
    return;
  }
  sinCosPolynomial(x, s, c);
}

[[noreturn]] SCANHEAD_COLD void miss(const char* surface)
{
  throw NumericalError(std::string("optical trace: the ray misses the ") + surface);
}

[[noreturn]] SCANHEAD_COLD void totalReflection(const char* surface)
{
  throw NumericalError(std::string("optical trace: total internal reflection at the ") + surface);
}

/// Moves the ray to the plane {x : (x - point).normal = 0}; \p dnormal, \p dpoint are the
/// derivatives of the plane w.r.t. joint \p k (ignored for k < 0: fixed plane).
template <bool kJ>
double moveToPlane(RayState& r, const Vec3& point, const Vec3& normal, int k, const Vec3& dpoint, const Vec3& dnormal,
                   const char* surface)
{
  const double den = r.d.dot(normal);
  if (!(std::abs(den) > kMinCosine))
  {
    miss(surface);
  }
  const double inv_den = 1.0 / den;
  const Vec3 gap = point - r.p;
  const double t = gap.dot(normal) * inv_den;
  if (!(t >= 0.0))
  {
    miss(surface);
  }
  if (kJ)
  {
    // t = ((P - p).n) / (d.n)  =>  dt = ((dP - dp).n + (P - p).dn - t (dd.n + d.dn)) / (d.n)
    for (int j = 0; j < 2; ++j)
    {
      double dnum = -r.dp.col(j).dot(normal);
      double dden = r.dd.col(j).dot(normal);
      if (j == k)
      {
        dnum += dpoint.dot(normal) + gap.dot(dnormal);
        dden += r.d.dot(dnormal);
      }
      const double dt = (dnum - t * dden) * inv_den;
      r.dp.col(j) += dt * r.d + t * r.dd.col(j);
    }
  }
  r.p += t * r.d;
  return den;
}

/// Reflection on a mirror turning with joint k: d' = d - 2 (d.n) n (SPEC §4).
template <bool kJ>
void reflect(RayState& r, const Vec3& n_c, const Vec3& n_s, const Vec3& n_0, const Vec3& p_c, const Vec3& p_s,
             const Vec3& p_0, double angle, int k, const char* surface)
{
  double s;
  double c;
  sinCos(angle, s, c);
  const Vec3 normal = c * n_c + s * n_s + n_0;
  const Vec3 point = c * p_c + s * p_s + p_0;
  Vec3 dnormal = Vec3::Zero();
  Vec3 dpoint = Vec3::Zero();
  if (kJ)
  {
    dnormal = c * n_s - s * n_c;
    dpoint = c * p_s - s * p_c;
  }
  const double den = moveToPlane<kJ>(r, point, normal, k, dpoint, dnormal, surface);
  if (!(den < 0.0))
  {
    miss(surface);  // the ray would reach the back of the mirror
  }
  if (kJ)
  {
    // dd' = dd - 2 ((dd.n + d.dn) n + (d.n) dn)
    for (int j = 0; j < 2; ++j)
    {
      double dden = r.dd.col(j).dot(normal);
      if (j == k)
      {
        dden += r.d.dot(dnormal);
        r.dd.col(j) -= 2.0 * den * dnormal;
      }
      r.dd.col(j) -= 2.0 * dden * normal;
    }
  }
  r.d -= 2.0 * den * normal;
}

/// Crosses a plane-parallel plate of thickness e (first face through \p point, unit \p normal,
/// second face e behind it along -normal), index ratio eta = n_gas / n_window. Vector Snell law
/// at the first face (SPEC §4), with N the normal facing the ray and c = -d.N:
///   d_g = eta d + (eta c - sqrt(k)) N,  k = 1 - eta^2 (1 - c^2),  and -d_g.N = sqrt(k);
/// the ray runs e / sqrt(k) inside; Snell at the parallel second face gives back d exactly.
template <bool kJ>
void crossPlate(RayState& r, const Vec3& point, const Vec3& normal, double thickness, double eta, const char* surface)
{
  const Vec3 zero = Vec3::Zero();
  moveToPlane<kJ>(r, point, normal, -1, zero, zero, surface);
  double cos_i = -r.d.dot(normal);
  const double sign = cos_i >= 0.0 ? 1.0 : -1.0;
  cos_i *= sign;
  const Vec3 facing = sign * normal;
  const double k = 1.0 - eta * eta * (1.0 - cos_i * cos_i);
  if (!(k > 0.0))
  {
    totalReflection(surface);
  }
  const double root = std::sqrt(k);
  const double inv_root = 1.0 / root;
  const Vec3 inside = eta * r.d + (eta * cos_i - root) * facing;
  const double length = thickness * inv_root;
  if (kJ)
  {
    // dcos_i = -dd.N, droot = eta^2 cos_i dcos_i / root, d(length) = -length droot / root
    for (int j = 0; j < 2; ++j)
    {
      const double dcos = -r.dd.col(j).dot(facing);
      const double droot = eta * eta * cos_i * dcos * inv_root;
      const Vec3 dinside = eta * r.dd.col(j) + (eta * dcos - droot) * facing;
      r.dp.col(j) += length * dinside - (length * droot * inv_root) * inside;
    }
  }
  r.p += length * inside;
}

// ---------------------------------------------------------------------------------------------
// The plain ray trace (no Jacobian) as one kernel over a number type T: T = double for trace(),
// T = Lanes (kLanes rays in the lanes of a GCC vector) for traceBlock(). Both instantiations
// perform the same IEEE operations (add, sub, mul, div, sqrt; no FMA: the build has no -mfma and
// the AVX2 clone does not enable it) in the same order, so a ray gives the same bits whichever
// way it is traced. The order is that of the Eigen expressions of traceImpl<true> (dot products
// (a0 b0 + a1 b1) + a2 b2, c·u + s·v + w left to right), checked bit for bit by the tests.

// Every lane helper is inlined into traceLanes (and its clones), so passing 32-byte vectors by
// value never crosses a call: GCC's note on their ABI without AVX does not apply.
#pragma GCC diagnostic ignored "-Wpsabi"
#define SCANHEAD_INLINE inline __attribute__((always_inline))

typedef double Lanes __attribute__((vector_size(32)));
typedef long long LaneMask __attribute__((vector_size(32)));
constexpr int kLanes = 4;

using detail::V3;

inline V3<double> v3(const Vec3& v)
{
  return {v.x(), v.y(), v.z()};
}

template <typename A, typename B>
SCANHEAD_INLINE auto dot(const V3<A>& a, const V3<B>& b)
{
  return (a.x * b.x + a.y * b.y) + a.z * b.z;
}

// Scalar/lane primitives. Masks: bool for double, LaneMask (all bits set = true) for Lanes.
SCANHEAD_INLINE double absOf(double x)
{
  return std::abs(x);
}
SCANHEAD_INLINE Lanes absOf(Lanes x)
{
  const LaneMask sign_off = (LaneMask{} + 0x7fffffffffffffffLL);
  return reinterpret_cast<Lanes>(reinterpret_cast<LaneMask>(x) & sign_off);
}
SCANHEAD_INLINE double sqrtOf(double x)
{
  return std::sqrt(x);
}
SCANHEAD_INLINE Lanes sqrtOf(Lanes x)
{
  // IEEE 754 sqrt is correctly rounded, so the packed instruction gives std::sqrt's bits lane by
  // lane (NaN for a negative lane, whose ray has failed anyway); unlike std::sqrt it has no errno
  // path, which kept the lane loop scalar with a libm call per lane.
#if defined(__SSE2__)
  // halves through registers (a store of two halves and a load of the whole would stall)
  typedef double Half __attribute__((vector_size(16)));
  const Half lo = __builtin_shufflevector(x, x, 0, 1);
  const Half hi = __builtin_shufflevector(x, x, 2, 3);
  const Half root_lo = reinterpret_cast<Half>(_mm_sqrt_pd(reinterpret_cast<__m128d>(lo)));
  const Half root_hi = reinterpret_cast<Half>(_mm_sqrt_pd(reinterpret_cast<__m128d>(hi)));
  return __builtin_shufflevector(root_lo, root_hi, 0, 1, 2, 3);
#else
  Lanes r;
  for (int i = 0; i < kLanes; ++i)
  {
    r[i] = __builtin_sqrt(x[i] < 0.0 ? std::numeric_limits<double>::quiet_NaN() : x[i]);
  }
  return r;
#endif
}
SCANHEAD_INLINE bool anyOf(LaneMask m)
{
  return ((m[0] | m[1]) | (m[2] | m[3])) != 0;
}
SCANHEAD_INLINE double selectOf(bool m, double a, double b)
{
  return m ? a : b;
}
SCANHEAD_INLINE Lanes selectOf(LaneMask m, Lanes a, Lanes b)
{
  return m ? a : b;
}

/// Two groups of kLanes rays, every operation issued for both: the trace is one long chain of
/// dependent operations (the sin/cos polynomials, a division per surface, two square roots), so
/// with one group the pipeline waits on latencies; two interleaved chains fill it. Each lane
/// still sees the same IEEE operations in the same order as trace().
struct Lanes2
{
  Lanes a, b;
};
struct Mask2
{
  LaneMask a, b;
};
#define SCANHEAD_LANES2_OP(op)                                         \
  SCANHEAD_INLINE Lanes2 operator op(const Lanes2& x, const Lanes2& y) \
  {                                                                    \
    return {x.a op y.a, x.b op y.b};                                   \
  }                                                                    \
  SCANHEAD_INLINE Lanes2 operator op(const Lanes2& x, double y)        \
  {                                                                    \
    return {x.a op y, x.b op y};                                       \
  }                                                                    \
  SCANHEAD_INLINE Lanes2 operator op(double x, const Lanes2& y)        \
  {                                                                    \
    return {x op y.a, x op y.b};                                       \
  }
SCANHEAD_LANES2_OP(+)
SCANHEAD_LANES2_OP(-)
SCANHEAD_LANES2_OP(*)
SCANHEAD_LANES2_OP(/)
#undef SCANHEAD_LANES2_OP
#define SCANHEAD_LANES2_CMP(op)                                \
  SCANHEAD_INLINE Mask2 operator op(const Lanes2& x, double y) \
  {                                                            \
    return {x.a op y, x.b op y};                               \
  }
SCANHEAD_LANES2_CMP(<)
SCANHEAD_LANES2_CMP(<=)
SCANHEAD_LANES2_CMP(>)
SCANHEAD_LANES2_CMP(>=)
#undef SCANHEAD_LANES2_CMP
SCANHEAD_INLINE Lanes2 operator-(const Lanes2& x)
{
  return {-x.a, -x.b};
}
SCANHEAD_INLINE Lanes2& operator*=(Lanes2& x, const Lanes2& y)
{
  x = x * y;
  return x;
}
SCANHEAD_INLINE Mask2 operator!(const Mask2& m)
{
  return {!m.a, !m.b};
}
SCANHEAD_INLINE Mask2& operator|=(Mask2& m, const Mask2& n)
{
  m.a |= n.a;
  m.b |= n.b;
  return m;
}
SCANHEAD_INLINE Lanes2 absOf(const Lanes2& x)
{
  return {absOf(x.a), absOf(x.b)};
}
SCANHEAD_INLINE Lanes2 sqrtOf(const Lanes2& x)
{
  return {sqrtOf(x.a), sqrtOf(x.b)};
}
SCANHEAD_INLINE Lanes2 selectOf(const Mask2& m, const Lanes2& x, const Lanes2& y)
{
  return {m.a ? x.a : y.a, m.b ? x.b : y.b};
}

/// Failure policy: the scalar trace throws at the first bad surface (as traceImpl does); the
/// lane trace records which lanes failed and carries on (their results are then discarded).
struct ThrowOnFailure
{
  void miss(bool bad, const char* surface) const
  {
    if (bad)
    {
      scanhead::miss(surface);
    }
  }
  void totalReflection(bool bad, const char* surface) const
  {
    if (bad)
    {
      scanhead::totalReflection(surface);
    }
  }
};

template <typename M>
struct RecordFailure
{
  M failed{};
  void miss(M bad, const char*) { failed |= bad; }
  void totalReflection(M bad, const char*) { failed |= bad; }
};

/// Lanes with |x| > 0.25 through libm, as sinCos() does.
SCANHEAD_INLINE void sinCosOutside(Lanes x, Lanes& s, Lanes& c)
{
  const LaneMask outside = !(absOf(x) <= 0.25);
  if (!anyOf(outside))
  {
    return;
  }
  for (int i = 0; i < kLanes; ++i)
  {
    if (outside[i] != 0)
    {
      double si;
      double ci;
      sinCos(x[i], si, ci);
      s[i] = si;
      c[i] = ci;
    }
  }
}

/// sin and cos of each lane with the scalar sinCos() polynomial (same operations); lanes with
/// |x| > 0.25 through libm, as sinCos() does.
SCANHEAD_INLINE void sinCos(Lanes x, Lanes& s, Lanes& c)
{
  sinCosPolynomial(x, s, c);
  sinCosOutside(x, s, c);
}

SCANHEAD_INLINE void sinCos(const Lanes2& x, Lanes2& s, Lanes2& c)
{
  sinCosPolynomial(x, s, c);
  sinCosOutside(x.a, s.a, c.a);
  sinCosOutside(x.b, s.b, c.b);
}

/// moveToPlane without derivatives: p += t d with t = ((P - p).n) / (d.n); returns d.n.
template <typename T, typename G, typename F>
SCANHEAD_INLINE T moveToPlaneK(V3<T>& p, const V3<T>& d, const V3<G>& point, const V3<G>& normal, F& fail,
                               const char* surface)
{
  const T den = dot(d, normal);
  fail.miss(!(absOf(den) > kMinCosine), surface);
  const T inv_den = 1.0 / den;
  const V3<T> gap{point.x - p.x, point.y - p.y, point.z - p.z};
  const T t = dot(gap, normal) * inv_den;
  fail.miss(!(t >= 0.0), surface);
  p = V3<T>{p.x + t * d.x, p.y + t * d.y, p.z + t * d.z};
  return den;
}

template <typename T, typename F>
SCANHEAD_INLINE void reflectK(V3<T>& p, V3<T>& d, const V3<double>& n_c, const V3<double>& n_s, const V3<double>& n_0,
                              const V3<double>& p_c, const V3<double>& p_s, const V3<double>& p_0, const T& angle,
                              F& fail, const char* surface)
{
  T s;
  T c;
  sinCos(angle, s, c);
  const V3<T> normal{c * n_c.x + s * n_s.x + n_0.x, c * n_c.y + s * n_s.y + n_0.y, c * n_c.z + s * n_s.z + n_0.z};
  const V3<T> point{c * p_c.x + s * p_s.x + p_0.x, c * p_c.y + s * p_s.y + p_0.y, c * p_c.z + s * p_s.z + p_0.z};
  const T den = moveToPlaneK(p, d, point, normal, fail, surface);
  fail.miss(!(den < 0.0), surface);
  const T twice = 2.0 * den;
  d = V3<T>{d.x - twice * normal.x, d.y - twice * normal.y, d.z - twice * normal.z};
}

template <typename T, typename F>
SCANHEAD_INLINE void crossPlateK(V3<T>& p, const V3<T>& d, const V3<double>& point, const V3<double>& normal,
                                 double thickness, double eta, F& fail, const char* surface)
{
  moveToPlaneK(p, d, point, normal, fail, surface);
  T cos_i = -dot(d, normal);
  const T sign = selectOf(cos_i >= 0.0, T{} + 1.0, T{} - 1.0);
  cos_i *= sign;
  const V3<T> facing{sign * normal.x, sign * normal.y, sign * normal.z};
  const T k = 1.0 - eta * eta * (1.0 - cos_i * cos_i);
  fail.totalReflection(!(k > 0.0), surface);
  const T root = sqrtOf(k);
  const T inv_root = 1.0 / root;
  const T bend = eta * cos_i - root;
  const V3<T> inside{eta * d.x + bend * facing.x, eta * d.y + bend * facing.y, eta * d.z + bend * facing.z};
  const T length = thickness * inv_root;
  p = V3<T>{p.x + length * inside.x, p.y + length * inside.y, p.z + length * inside.z};
}

/// The whole plain trace: spot (x, y) in the work-plane frame and the direction there.
template <typename T, typename F>
SCANHEAD_INLINE void traceKernel(const detail::TraceSurfaces& g, const T& q_x, const T& q_y, F& fail, T& spot_x,
                                 T& spot_y, V3<T>& direction)
{
  V3<T> p{T{} + g.source_point.x, T{} + g.source_point.y, T{} + g.source_point.z};
  V3<T> d{T{} + g.source_direction.x, T{} + g.source_direction.y, T{} + g.source_direction.z};
  reflectK(p, d, g.mx_n_c, g.mx_n_s, g.mx_n_0, g.mx_p_c, g.mx_p_s, g.mx_p_0, q_x, fail, "mirror X");
  reflectK(p, d, g.my_n_c, g.my_n_s, g.my_n_0, g.my_p_c, g.my_p_s, g.my_p_0, q_y, fail, "mirror Y");
  crossPlateK(p, d, g.w1_point, g.w1_normal, g.thickness, g.eta, fail, "window 1");
  crossPlateK(p, d, g.w2_point, g.w2_normal, g.thickness, g.eta, fail, "window 2");
  moveToPlaneK(p, d, g.plane_point, g.plane_normal, fail, "work plane");
  const V3<T> rel{p.x - g.plane_point.x, p.y - g.plane_point.y, p.z - g.plane_point.z};
  spot_x = dot(g.rt0, rel);
  spot_y = dot(g.rt1, rel);
  direction = V3<T>{dot(g.rt0, d), dot(g.rt1, d), dot(g.rt2, d)};
}

/// Rays per step of traceLanes: two groups of kLanes (Lanes2).
constexpr std::size_t kStepRays = 2 * kLanes;

/// traceKernel over \p n rays (n a multiple of kStepRays), kStepRays at a time; returns the
/// number of rays that failed (their outputs are NaN). Cloned for AVX2 (same operations, so same
/// bits).
__attribute__((target_clones("arch=x86-64-v4", "avx2", "default"))) std::size_t traceLanes(
    const detail::TraceSurfaces& g, std::size_t n, const double* q_x, const double* q_y, double* spot_x, double* spot_y,
    double* dir_x, double* dir_y, double* dir_z)
{
  std::size_t failures = 0;
  const Lanes nan = Lanes{} + std::numeric_limits<double>::quiet_NaN();
  auto load = [](const double* p) {
    Lanes2 v;
    std::memcpy(&v.a, p, sizeof(Lanes));
    std::memcpy(&v.b, p + kLanes, sizeof(Lanes));
    return v;
  };
  auto store = [&nan](double* p, const Lanes2& v, const Mask2& failed) {
    const Lanes a = failed.a ? nan : v.a;
    const Lanes b = failed.b ? nan : v.b;
    std::memcpy(p, &a, sizeof(Lanes));
    std::memcpy(p + kLanes, &b, sizeof(Lanes));
  };
  for (std::size_t k = 0; k < n; k += kStepRays)
  {
    const Lanes2 qx = load(q_x + k);
    const Lanes2 qy = load(q_y + k);
    RecordFailure<Mask2> fail;
    Lanes2 sx;
    Lanes2 sy;
    V3<Lanes2> dir;
    traceKernel(g, qx, qy, fail, sx, sy, dir);
    store(spot_x + k, sx, fail.failed);
    store(spot_y + k, sy, fail.failed);
    if (dir_x != nullptr)
    {
      store(dir_x + k, dir.x, fail.failed);
      store(dir_y + k, dir.y, fail.failed);
      store(dir_z + k, dir.z, fail.failed);
    }
    if (anyOf(fail.failed.a | fail.failed.b))
    {
      for (int i = 0; i < kLanes; ++i)
      {
        failures += (fail.failed.a[i] != 0 ? 1 : 0) + (fail.failed.b[i] != 0 ? 1 : 0);
      }
    }
  }
  return failures;
}
}  // namespace

OpticalModel::OpticalModel(const OpticalGeometry& geometry, const OpticsConfig& config)
  : geometry_(geometry)
  , config_(config)
{
  source_point_ = geometry_.source.translation();
  source_direction_ = geometry_.source.linear().col(0);

  // mirror frame in base at angle q: mount * Rz(q) * rel; Rz(q) v = cos q (vx, vy, 0) +
  // sin q (-vy, vx, 0) + (0, 0, vz).
  auto terms = [](const Eigen::Isometry3d& mount, const Eigen::Isometry3d& rel) {
    const Eigen::Matrix3d& r = mount.linear();
    const Vec3 n = rel.linear().col(0);
    const Vec3 p = rel.translation();
    MirrorTerms m;
    m.n_c = r * Vec3(n.x(), n.y(), 0.0);
    m.n_s = r * Vec3(-n.y(), n.x(), 0.0);
    m.n_0 = r * Vec3(0.0, 0.0, n.z());
    m.p_c = r * Vec3(p.x(), p.y(), 0.0);
    m.p_s = r * Vec3(-p.y(), p.x(), 0.0);
    m.p_0 = r * Vec3(0.0, 0.0, p.z()) + mount.translation();
    return m;
  };
  mirror_x_terms_ = terms(geometry_.mount_x, geometry_.mirror_x);
  mirror_y_terms_ = terms(geometry_.mount_y, geometry_.mirror_y);

  window_1_point_ = geometry_.window_1.translation();
  window_1_normal_ = geometry_.window_1.linear().col(2);
  window_2_point_ = geometry_.window_2.translation();
  window_2_normal_ = geometry_.window_2.linear().col(2);

  plane_point_ = geometry_.work_plane.translation();
  plane_normal_ = geometry_.work_plane.linear().col(2);
  plane_rotation_t_ = geometry_.work_plane.linear().transpose();
  eta_ = config_.n_gas / config_.n_window;

  auto surfaces = std::make_shared<detail::TraceSurfaces>();
  detail::TraceSurfaces& g = *surfaces;
  g.source_point = v3(source_point_);
  g.source_direction = v3(source_direction_);
  const MirrorTerms& mx = mirror_x_terms_;
  const MirrorTerms& my = mirror_y_terms_;
  g.mx_n_c = v3(mx.n_c), g.mx_n_s = v3(mx.n_s), g.mx_n_0 = v3(mx.n_0);
  g.mx_p_c = v3(mx.p_c), g.mx_p_s = v3(mx.p_s), g.mx_p_0 = v3(mx.p_0);
  g.my_n_c = v3(my.n_c), g.my_n_s = v3(my.n_s), g.my_n_0 = v3(my.n_0);
  g.my_p_c = v3(my.p_c), g.my_p_s = v3(my.p_s), g.my_p_0 = v3(my.p_0);
  g.w1_point = v3(window_1_point_), g.w1_normal = v3(window_1_normal_);
  g.w2_point = v3(window_2_point_), g.w2_normal = v3(window_2_normal_);
  g.plane_point = v3(plane_point_), g.plane_normal = v3(plane_normal_);
  g.rt0 = v3(plane_rotation_t_.row(0).transpose());
  g.rt1 = v3(plane_rotation_t_.row(1).transpose());
  g.rt2 = v3(plane_rotation_t_.row(2).transpose());
  g.thickness = config_.window_thickness_m;
  g.eta = eta_;
  surfaces_ = std::move(surfaces);
}

template <bool kWithJacobian, bool kRecord>
OpticalModel::Ray OpticalModel::traceImpl(const Eigen::Vector2d& q, Eigen::Matrix2d* jacobian,
                                          std::vector<Eigen::Vector3d>* points) const
{
  RayState r;
  r.p = source_point_;
  r.d = source_direction_;
  // beamPoints() only (kRecord): the hot instantiations keep the ray state in registers.
  auto record = [&points](const Vec3& p) {
    if constexpr (kRecord)
      points->push_back(p);
    else
    {
      (void)points;
      (void)p;
    }
  };
  record(r.p);
  if (kWithJacobian)
  {
    r.dp.setZero();
    r.dd.setZero();
  }
  const MirrorTerms& mx = mirror_x_terms_;
  const MirrorTerms& my = mirror_y_terms_;
  reflect<kWithJacobian>(r, mx.n_c, mx.n_s, mx.n_0, mx.p_c, mx.p_s, mx.p_0, q.x(), 0, "mirror X");
  record(r.p);
  reflect<kWithJacobian>(r, my.n_c, my.n_s, my.n_0, my.p_c, my.p_s, my.p_0, q.y(), 1, "mirror Y");
  record(r.p);
  const double e = config_.window_thickness_m;
  crossPlate<kWithJacobian>(r, window_1_point_, window_1_normal_, e, eta_, "window 1");
  record(r.p);
  crossPlate<kWithJacobian>(r, window_2_point_, window_2_normal_, e, eta_, "window 2");
  record(r.p);
  const Vec3 zero = Vec3::Zero();
  moveToPlane<kWithJacobian>(r, plane_point_, plane_normal_, -1, zero, zero, "work plane");
  record(r.p);

  Ray ray;
  ray.spot = (plane_rotation_t_ * (r.p - plane_point_)).head<2>();
  ray.direction = plane_rotation_t_ * r.d;  // unit: reflections and Snell keep |d| = 1
  if (kWithJacobian)
  {
    *jacobian = plane_rotation_t_.topRows<2>() * r.dp;
  }
  return ray;
}

OpticalModel::Ray OpticalModel::trace(const Eigen::Vector2d& q) const
{
  const ThrowOnFailure fail;
  double spot_x;
  double spot_y;
  V3<double> d;
  traceKernel(*surfaces_, q.x(), q.y(), fail, spot_x, spot_y, d);
  Ray ray;
  ray.spot = Eigen::Vector2d(spot_x, spot_y);
  ray.direction = Eigen::Vector3d(d.x, d.y, d.z);  // unit: reflections and Snell keep |d| = 1
  return ray;
}

std::vector<Eigen::Vector3d> OpticalModel::beamPoints(const Eigen::Vector2d& q) const
{
  std::vector<Eigen::Vector3d> points;
  points.reserve(6);
  traceImpl<false, true>(q, nullptr, &points);
  return points;
}

std::size_t OpticalModel::traceBlock(std::size_t n, const double* q_x, const double* q_y, double* spot_x,
                                     double* spot_y, double* dir_x, double* dir_y, double* dir_z) const
{
  const bool directions = dir_x != nullptr && dir_y != nullptr && dir_z != nullptr;
  const std::size_t whole = n - n % kStepRays;
  std::size_t failures =
      traceLanes(*surfaces_, whole, q_x, q_y, spot_x, spot_y, directions ? dir_x : nullptr, dir_y, dir_z);
  if (whole < n)
  {
    // The last partial block, padded with copies of its first ray.
    double in_x[kStepRays];
    double in_y[kStepRays];
    double out[5][kStepRays];
    for (std::size_t i = 0; i < kStepRays; ++i)
    {
      const std::size_t k = whole + (whole + i < n ? i : 0);
      in_x[i] = q_x[k];
      in_y[i] = q_y[k];
    }
    traceLanes(*surfaces_, kStepRays, in_x, in_y, out[0], out[1], out[2], out[3], out[4]);
    for (std::size_t k = whole; k < n; ++k)
    {
      const std::size_t i = k - whole;
      spot_x[k] = out[0][i];
      spot_y[k] = out[1][i];
      if (directions)
      {
        dir_x[k] = out[2][i];
        dir_y[k] = out[3][i];
        dir_z[k] = out[4][i];
      }
      failures += std::isnan(out[0][i]) ? 1 : 0;
    }
  }
  return failures;
}

SCANHEAD_FLATTEN OpticalModel::Ray OpticalModel::traceWithJacobian(const Eigen::Vector2d& q,
                                                                   Eigen::Matrix2d& jacobian) const
{
  return traceImpl<true>(q, &jacobian, nullptr);
}

Eigen::Matrix2d OpticalModel::jacobian(const Eigen::Vector2d& q) const
{
  Eigen::Matrix2d j;
  traceWithJacobian(q, j);
  return j;
}

Eigen::Vector2d OpticalModel::inverse(const Eigen::Vector2d& spot, const Eigen::Vector2d& q_guess) const
{
  auto unreachable = [&spot](const std::string& why) -> NumericalError {
    std::ostringstream msg;
    msg << "spot (" << spot.x() * 1e3 << ", " << spot.y() * 1e3 << ") mm not reachable: " << why;
    return NumericalError(msg.str());
  };
  // Simplified Newton: J is re-evaluated only once q is more than kJacobianReuse_rad away from
  // where it was last evaluated. The relative change of J over that distance (< ~1e-3) is the
  // contraction factor of a step with a stale J, so convergence stays fast, and the final
  // iterations of a warm-started inverse cost a plain trace instead of a trace with Jacobian.
  constexpr double kJacobianReuse_rad = 1e-3;
  Eigen::Vector2d q = q_guess;
  Eigen::Vector2d q_of_j = q;
  Eigen::Matrix2d j_inverse = Eigen::Matrix2d::Zero();
  bool have_j = false;
  for (int iteration = 0;; ++iteration)
  {
    Eigen::Vector2d error;
    const bool refresh = !have_j || (q - q_of_j).cwiseAbs().maxCoeff() > kJacobianReuse_rad;
    Eigen::Matrix2d j;
    try
    {
      error = spot - (refresh ? traceWithJacobian(q, j) : trace(q)).spot;
    }
    catch (const NumericalError& e)
    {
      throw unreachable(e.what());
    }
    const double residual_m = error.norm();
    if (residual_m <= config_.newton_tolerance_m)
    {
      break;
    }
    if (iteration >= config_.newton_max_iterations)
    {
      std::ostringstream why;
      why << "Newton did not converge in " << config_.newton_max_iterations << " iterations (residual " << residual_m
          << " m)";
      throw unreachable(why.str());
    }
    if (refresh)
    {
      const double det = j.determinant();
      if (!(std::abs(det) > 1e-12))
      {
        throw unreachable("singular Jacobian");
      }
      // 2x2 inverse in closed form: J^-1 = [j11 -j01; -j10 j00] / det
      j_inverse << j(1, 1), -j(0, 1), -j(1, 0), j(0, 0);
      j_inverse /= det;
      q_of_j = q;
      have_j = true;
    }
    q += j_inverse * error;
    if (!std::isfinite(q.x()) || !std::isfinite(q.y()))
    {
      throw unreachable("Newton diverged");
    }
  }
  const double lo = geometry_.joint_lower_rad;
  const double hi = geometry_.joint_upper_rad;
  if (q.x() < lo || q.x() > hi || q.y() < lo || q.y() > hi)
  {
    std::ostringstream why;
    why << "angles (" << q.x() << ", " << q.y() << ") rad outside the joint limits [" << lo << ", " << hi << "]";
    throw unreachable(why.str());
  }
  return q;
}

Eigen::Isometry3d OpticalModel::mirrorXPose(double angle_rad) const
{
  return geometry_.mount_x * Eigen::AngleAxisd(angle_rad, Vec3::UnitZ()) * geometry_.mirror_x;
}

Eigen::Isometry3d OpticalModel::mirrorYPose(double angle_rad) const
{
  return geometry_.mount_y * Eigen::AngleAxisd(angle_rad, Vec3::UnitZ()) * geometry_.mirror_y;
}
}  // namespace scanhead
