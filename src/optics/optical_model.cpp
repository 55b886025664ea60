/// \file optical_model.cpp
/// \brief Ray trace (with forward-mode Jacobian) and Newton inverse of the two-mirror head.
#include "scanhead/optics/optical_model.hpp"

#include <cmath>
#include <sstream>

#include "scanhead/common/errors.hpp"

namespace scanhead
{
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
  // Coefficients (-1)^k / (2k+1)! and (-1)^k / (2k)!, folded at compile time.
  const double z = x * x;
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
}

template <bool kWithJacobian>
OpticalModel::Ray OpticalModel::traceImpl(const Eigen::Vector2d& q, Eigen::Matrix2d* jacobian) const
{
  RayState r;
  r.p = source_point_;
  r.d = source_direction_;
  if (kWithJacobian)
  {
    r.dp.setZero();
    r.dd.setZero();
  }
  const MirrorTerms& mx = mirror_x_terms_;
  const MirrorTerms& my = mirror_y_terms_;
  reflect<kWithJacobian>(r, mx.n_c, mx.n_s, mx.n_0, mx.p_c, mx.p_s, mx.p_0, q.x(), 0, "mirror X");
  reflect<kWithJacobian>(r, my.n_c, my.n_s, my.n_0, my.p_c, my.p_s, my.p_0, q.y(), 1, "mirror Y");
  const double e = config_.window_thickness_m;
  crossPlate<kWithJacobian>(r, window_1_point_, window_1_normal_, e, eta_, "window 1");
  crossPlate<kWithJacobian>(r, window_2_point_, window_2_normal_, e, eta_, "window 2");
  const Vec3 zero = Vec3::Zero();
  moveToPlane<kWithJacobian>(r, plane_point_, plane_normal_, -1, zero, zero, "work plane");

  Ray ray;
  ray.spot = (plane_rotation_t_ * (r.p - plane_point_)).head<2>();
  ray.direction = plane_rotation_t_ * r.d;  // unit: reflections and Snell keep |d| = 1
  if (kWithJacobian)
  {
    *jacobian = plane_rotation_t_.topRows<2>() * r.dp;
  }
  return ray;
}

SCANHEAD_FLATTEN OpticalModel::Ray OpticalModel::trace(const Eigen::Vector2d& q) const
{
  return traceImpl<false>(q, nullptr);
}

SCANHEAD_FLATTEN OpticalModel::Ray OpticalModel::traceWithJacobian(const Eigen::Vector2d& q,
                                                                   Eigen::Matrix2d& jacobian) const
{
  return traceImpl<true>(q, &jacobian);
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
