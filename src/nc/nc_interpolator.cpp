/// \file nc_interpolator.cpp
/// \brief The NC stage (SPEC §2): NC program → X_inter → IGT → FIR T1 → velocity saturation →
/// FIR T2 → Q_filt2 (or the adaptive filter in the plane → IGT), the laser gate aligned on the
/// filtered setpoint, optional power modulation and XY2-100 quantisation. The IGT warm start, the
/// exact derivatives of Q_filt2 and the plane speed for power ∝ speed are derived in
/// nc_interpolator.hpp.
#include "scanhead/nc/nc_interpolator.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>

#include "scanhead/common/box_filter.hpp"
#include "scanhead/common/errors.hpp"
#include "scanhead/common/number_text.hpp"
#include "scanhead/job/path_timeline.hpp"
#include "scanhead/nc/adaptive_fir.hpp"
#include "scanhead/nc/rate_limiter.hpp"
#include "scanhead/optics/correction_table.hpp"
#include "scanhead/optics/joint_gain.hpp"
#include "scanhead/servo/galvo_servo.hpp"

namespace scanhead
{
namespace
{
/// ceil(x) where x within 1e-9 (relative) of an integer counts as that integer.
std::uint64_t ceilSnapped(double x)
{
  const double nearest = std::round(x);
  if (std::abs(x - nearest) <= 1e-9 * std::max(1.0, std::abs(x)))
  {
    return static_cast<std::uint64_t>(std::max(0.0, nearest));
  }
  return static_cast<std::uint64_t>(std::max(0.0, std::ceil(x)));
}

/// "(x, y) m" with 9 significant digits ("%.9g") for messages.
std::string pointText(const Eigen::Vector2d& p)
{
  return "(" + significantText(p.x(), 9) + ", " + significantText(p.y(), 9) + ") m";
}

Recipe followFilteredSetpoint(const NcConfig& config)
{
  Recipe recipe;
  recipe.laser_on_delay_s = config.filterDelay();
  recipe.laser_off_delay_s = config.filterDelay();
  return recipe;
}

constexpr double kLimitSlack = 1.0 + 1e-6;  ///< relative slack before a sample counts as over a limit

/// Nodes per axis of the Newton IGT's predictor table (bicubic error < 0.05 nm, built in ~2.5 ms).
constexpr int kPredictorNodes = 65;

/// J̇·q̇ = (dJ/dt)·q̇, the curvature term of ẍ = J q̈ + J̇ q̇: a central difference of the Jacobian
/// along q̇ (steps of 1e-6 rad: truncation ~1e-12, rounding ~1e-10 relative).
Eigen::Vector2d jacobianRateTimesVelocity(const OpticalModel& optics, const Eigen::Vector2d& q,
                                          const Eigen::Vector2d& q_dot)
{
  const double speed = q_dot.norm();
  if (speed == 0.0)
  {
    return Eigen::Vector2d::Zero();
  }
  constexpr double kStep_rad = 1e-6;
  const Eigen::Vector2d u = q_dot / speed;
  const Eigen::Matrix2d rate =
      (optics.jacobian(q + kStep_rad * u) - optics.jacobian(q - kStep_rad * u)) * (speed / (2.0 * kStep_rad));
  return rate * q_dot;
}

/// q += M (x − spot), point by point (vectorised across points; no FMA, so every clone gives
/// the same bits).
__attribute__((target_clones("avx2", "default"))) void newtonStep(
    std::size_t n, const double* __restrict x, const double* __restrict y, const double* __restrict spot_x,
    const double* __restrict spot_y, const double* __restrict m00, const double* __restrict m01,
    const double* __restrict m10, const double* __restrict m11, double* __restrict q_x, double* __restrict q_y)
{
  for (std::size_t i = 0; i < n; ++i)
  {
    const double e_x = x[i] - spot_x[i];
    const double e_y = y[i] - spot_y[i];
    q_x[i] += m00[i] * e_x + m01[i] * e_y;
    q_y[i] += m10[i] * e_x + m11[i] * e_y;
  }
}
}  // namespace

/// The inverse geometric transform: Newton on the optics, or the correction table.
struct NcInterpolator::Igt
{
  bool use_table = false;
  CorrectionTable table;
  TableInterpolation interpolation = TableInterpolation::Bilinear;
  /// Newton: the start of every sample's Newton (bicubic 65 × 65 table over the field and the
  /// nodes' J⁻¹, bilinear); absent if the optics cannot reach a node (then the sequential warm start).
  bool have_predictor = false;
  CorrectionTable predictor;
  // scratch of solveBlock (structure of arrays)
  std::vector<double> q_x, q_y, spot_x, spot_y, m00, m01, m10, m11;

  Eigen::Vector2d solve(const OpticalModel& optics, const Eigen::Vector2d& x, const Eigen::Vector2d& guess) const
  {
    if (use_table)
    {
      return table.joints(x, interpolation);
    }
    try
    {
      return optics.inverse(x, guess);
    }
    catch (const NumericalError&)
    {
      return optics.inverse(x, Eigen::Vector2d::Zero());
    }
  }

  /// \brief Newton IGT of \p n points (x[i], y[i]) at once, each independent of the others (so of
  /// chunking): q⁰ from the predictor table, whose error is < 0.05 nm on the plane
  /// (correction_table.hpp), then one simplified Newton step q¹ = q⁰ + M (x − h(q⁰)) with M the
  /// interpolated J⁻¹ (contraction |I − M J| ≲ 1e-4, so |x − h(q¹)| ~ 1e-16 m). Both residuals
  /// are traced (OpticalModel::traceBlock, bit-identical to trace()): a point is accepted, as by
  /// OpticalModel::inverse, only where |x − h(q)| <= newton_tolerance_m and q is within the joint
  /// limits. Elsewhere ok[i] = 0 and q[i] is the best start for the scalar Newton. Structure of
  /// arrays throughout (CorrectionTable::predictBlock).
  /// \pre have_predictor
  void solveBlock(const OpticalModel& optics, std::size_t n, const double* x, const double* y, Eigen::Vector2d* q,
                  unsigned char* ok)
  {
    q_x.resize(n);
    q_y.resize(n);
    spot_x.resize(n);
    spot_y.resize(n);
    m00.resize(n);
    m01.resize(n);
    m10.resize(n);
    m11.resize(n);
    predictor.predictBlock(n, x, y, q_x.data(), q_y.data(), m00.data(), m01.data(), m10.data(), m11.data(), ok);
    // The step is taken even where q⁰ is already within the tolerance (about 1 point in 20): it
    // costs nothing (the second trace is done for the block anyway) and leaves ~1e-16 m.
    const double tolerance = optics.config().newton_tolerance_m;
    optics.traceBlock(n, q_x.data(), q_y.data(), spot_x.data(), spot_y.data());
    newtonStep(n, x, y, spot_x.data(), spot_y.data(), m00.data(), m01.data(), m10.data(), m11.data(), q_x.data(),
               q_y.data());
    optics.traceBlock(n, q_x.data(), q_y.data(), spot_x.data(), spot_y.data());
    const double lo = optics.geometry().joint_lower_rad;
    const double hi = optics.geometry().joint_upper_rad;
    for (std::size_t i = 0; i < n; ++i)
    {
      const double e_x = x[i] - spot_x[i];
      const double e_y = y[i] - spot_y[i];
      // the criterion of OpticalModel::inverse, |error| <= tol (false for NaN: a ray that failed)
      const bool converged = ok[i] == 1 && std::sqrt(e_x * e_x + e_y * e_y) <= tolerance;
      const bool inside = q_x[i] >= lo && q_x[i] <= hi && q_y[i] >= lo && q_y[i] <= hi;
      ok[i] = (converged && inside) ? 1 : 0;
      const bool finite = std::isfinite(q_x[i]) && std::isfinite(q_y[i]);
      q[i] = finite ? Eigen::Vector2d(q_x[i], q_y[i]) : Eigen::Vector2d::Zero();
    }
  }
};

struct NcInterpolator::State
{
  NcPlan plan;
  PathTimeline::Cursor path_cursor;
  LaserGate::Cursor gate_cursor;
  bool adaptive = false;
  // fixed filters (joint space), and their twin on X_inter for the plane speed
  BoxFilter<2> fir1;
  RateLimiter limiter;
  BoxFilter<4> fir2;  ///< channels: s (2), ṡ (2)
  BoxFilter<2> plane_fir1;
  BoxFilter<2> plane_fir2;
  BoxFilter<2> inter_rate_fir1;  ///< debug: box T1 of the Q_inter velocity → Q_filt1 acceleration
  // adaptive filter (plane)
  AdaptiveFir adaptive_fir;
  AdaptiveFir::Cursor filt2_cursor;
  AdaptiveFir::Cursor filt1_cursor;
  Eigen::Vector2d x_prev = Eigen::Vector2d::Constant(std::numeric_limits<double>::quiet_NaN());
  Eigen::Vector2d q_prev = Eigen::Vector2d::Zero();        ///< IGT output at the last sample [rad]
  Eigen::Vector2d q_prev2 = Eigen::Vector2d::Zero();       ///< one sample before [rad]
  Eigen::Vector2d q_inter_prev = Eigen::Vector2d::Zero();  ///< debug, adaptive: Q_inter history
  Eigen::Vector2d q_inter_prev2 = Eigen::Vector2d::Zero();
  Eigen::Vector2d accel_prev = Eigen::Vector2d::Zero();
  std::vector<double> plane_speeds;  ///< per sample of the chunk: speed the power follows [m/s]
  // per sample of the chunk: X_inter, the IGT's point (X_inter, or X_filt2 adaptive), its solution
  std::vector<Eigen::Vector2d> x_inter;
  std::vector<PlaneState> filt2;
  std::vector<Eigen::Vector2d> igt_point;
  std::vector<Eigen::Vector2d> q_igt;
  std::vector<std::size_t> distinct;           ///< samples whose IGT point differs from the one before
  std::vector<double> distinct_x, distinct_y;  ///< their points [m]
  std::vector<Eigen::Vector2d> distinct_q;     ///< their solutions
  std::vector<unsigned char> distinct_ok;      ///< accepted by the block IGT
  // per sample of the chunk, fixed filters: Q_filt1 and its velocity, s and ṡ, FIR T2's output and
  // derivative, and the plane filters (power ∝ speed)
  std::vector<Eigen::Vector2d> q_filt1, q_filt1_dot;
  std::vector<Eigen::Vector4d> s_and_rate, filt2_average, filt2_derivative;
  std::vector<Eigen::Vector2d> plane_average, plane_average2, plane_derivative;
  std::unique_ptr<GalvoServo> predictor;  ///< power_mode "predicted": the servo model on the setpoint
  std::uint64_t next = 0;
  std::string job_name;
  NcStats stats;
};

NcInterpolator::NcInterpolator(const NcConfig& config, const Recipe& recipe, const OpticalModel& optics,
                               const ServoConfig* servo_model)
  : config_(config)
  , recipe_(recipe)
  , optics_(optics)
  , igt_(std::make_unique<Igt>())
{
  config_.validate();
  if (servo_model != nullptr)
  {
    servo_delay_s_ = GalvoServo(*servo_model, config_.period_s).lowFrequencyDelay().maxCoeff();
  }
  if (config_.power_mode == "predicted")
  {
    if (servo_model == nullptr)
    {
      throw ConfigError("nc.power_mode: 'predicted' needs the servo model (this NC was built without one)");
    }
    servo_model_ = std::make_unique<ServoConfig>(*servo_model);
  }
  if (config_.cap_speeds && config_.filter_mode == "fixed" && !(config_.fir_t1_s > 0.0 && config_.fir_t2_s > 0.0))
  {
    throw ConfigError(
        "nc.cap_speeds needs nc.fir_t1_s and nc.fir_t2_s > 0 (fixed filters of zero duration "
        "cannot keep any speed within the acceleration and jerk limits)");
  }
  if (config_.igt.mode == "table")
  {
    igt_->use_table = true;
    igt_->interpolation = parseTableInterpolation(config_.igt.table_interpolation, "nc.igt.table_interpolation");
    igt_->table = config_.igt.table_file.empty()
                      ? CorrectionTable::build(optics_, config_.igt.table_nodes, optics_.config().field_half_width_m)
                      : CorrectionTable::load(config_.igt.table_file);
  }
  else
  {
    try
    {
      igt_->predictor = CorrectionTable::build(optics_, kPredictorNodes, optics_.config().field_half_width_m);
      igt_->have_predictor = true;
    }
    catch (const NumericalError&)
    {
      igt_->have_predictor = false;  // a node out of reach: every sample warm-started from the last
    }
  }
  if (config_.filter_mode == "adaptive" || config_.cap_speeds)
  {
    joint_gains_ = jointRateGains(optics_, optics_.config().field_half_width_m);
  }
}

NcInterpolator::NcInterpolator(const NcConfig& config, const OpticalModel& optics)
  : NcInterpolator(config, followFilteredSetpoint(config), optics)
{
}

NcInterpolator::~NcInterpolator() = default;

void NcInterpolator::start(const Job& job)
{
  state_.reset();
  auto st = std::make_unique<State>();
  st->job_name = job.name;
  st->adaptive = (config_.filter_mode == "adaptive");

  const double g = joint_gains_.maxCoeff();  // rad/m; 0 when the limits are not used
  const double speed_cap = config_.speedCap(g);
  NcProgramOptions options = NcProgramOptions::from(config_, recipe_);
  options.speed_cap_mps = speed_cap;
  NcPlan& plan = st->plan;
  plan.program = buildNcProgram(job, options);
  const PathTimeline& timeline = plan.program.timeline;
  if (!timeline.hasPoints())
  {
    throw InputError("NC: job '" + job.name + "' has no move (no point, or all its points are the same)");
  }

  // Every point the program visits (skywriting adds some) must be reachable; checked now so a
  // bad job fails at start, not mid-stream. Each from the previous solution, retried from 0.
  Eigen::Vector2d q = Eigen::Vector2d::Zero();
  auto reach = [&](const Eigen::Vector2d& x, const std::string& what) {
    try
    {
      q = igt_->solve(optics_, x, q);
    }
    catch (const NumericalError& e)
    {
      throw NumericalError("NC: job '" + job.name + "' " + what + " " + pointText(x) +
                           " is not reachable by the optics: " + e.what());
    }
  };
  reach(timeline.startPoint(), "start point");
  const Eigen::Vector2d q0 = q;
  for (const PathSegment& seg : timeline.segments())
  {
    // A move ends at the vertex after its start; an inserted jump, a dwell or a hold at its own.
    const std::size_t vertex = (seg.implicit_jump || seg.dwell || seg.delay) ? seg.vertex : seg.vertex + 1;
    const std::string what = seg.skywriting
                                 ? "skywriting point (polyline " + std::to_string(seg.polyline) + ")"
                                 : "polyline " + std::to_string(seg.polyline) + " point " + std::to_string(vertex);
    reach(seg.end_m, what);
  }

  const double ts = config_.period_s;
  double filter_delay_s = config_.filterDelay();
  if (st->adaptive)
  {
    const PlaneLimits limits{config_.max_joint_accel_radps2 / g, config_.max_joint_jerk_radps3 / g};
    st->adaptive_fir = AdaptiveFir(timeline, limits);
    filter_delay_s = st->adaptive_fir.delay();
    plan.gate_shift_s = filter_delay_s - config_.filterDelay();
    plan.longest_t1_s = st->adaptive_fir.longest().t1_s;
    plan.longest_t2_s = st->adaptive_fir.longest().t2_s;
  }
  else
  {
    st->fir1 = BoxFilter<2>(config_.fir_t1_s, ts);
    st->fir1.reset(q0);
    st->limiter = RateLimiter(config_.max_joint_speed_radps, ts);
    st->limiter.reset(q0);
    st->fir2 = BoxFilter<4>(config_.fir_t2_s, ts);
    Eigen::Vector4d s0;
    s0 << q0, 0.0, 0.0;
    st->fir2.reset(s0);
    st->plane_fir1 = BoxFilter<2>(config_.fir_t1_s, ts);
    st->plane_fir1.reset(timeline.startPoint());
    st->plane_fir2 = BoxFilter<2>(config_.fir_t2_s, ts);
    st->plane_fir2.reset(timeline.startPoint());
    st->inter_rate_fir1 = BoxFilter<2>(config_.fir_t1_s, ts);
    st->inter_rate_fir1.reset(Eigen::Vector2d::Zero());
    plan.longest_t1_s = config_.fir_t1_s;
    plan.longest_t2_s = config_.fir_t2_s;
  }
  st->x_prev = timeline.startPoint();
  st->q_prev = q0;
  st->q_prev2 = q0;  // at rest before the start
  st->q_inter_prev = q0;
  st->q_inter_prev2 = q0;
  if (servo_model_)
  {
    st->predictor = std::make_unique<GalvoServo>(*servo_model_, ts);
  }

  // Samples n = 0 .. N−1 cover the program, the filters' settling (2·delay) and the last laser
  // window, then the tail (a time within 1e-9 relative of a sample counts as on it).
  double end_s = timeline.duration() + 2.0 * filter_delay_s;
  const auto& windows = plan.program.gate.windows();
  if (!windows.empty())
  {
    end_s = std::max(end_s, windows.back().off_s + plan.gate_shift_s);
  }
  plan.total_samples = ceilSnapped((end_s + config_.tail_s) / ts) + 1;
  plan.job_name = job.name;
  plan.period_s = ts;
  plan.speed_cap_mps = speed_cap;
  plan.filter_delay_s = filter_delay_s;
  plan.start_joints_rad = q0;
  plan.servo_delay_s = servo_delay_s_;
  st->stats = ncStatsOf(plan);  // the per-sample figures start at zero
  state_ = std::move(st);
}

NcOutput NcInterpolator::process(std::size_t max_samples)
{
  NcOutput out;
  const double ts = config_.period_s;
  out.setpoint.period_s = ts;
  out.laser.period_s = ts;
  out.debug.period_s = ts;
  if (!state_)
  {
    return out;
  }
  State& st = *state_;
  out.setpoint.first_index = st.next;
  out.laser.first_index = st.next;
  out.debug.first_index = st.next;
  const std::uint64_t remaining = st.plan.total_samples - st.next;
  const std::size_t count = static_cast<std::size_t>(std::min<std::uint64_t>(max_samples, remaining));
  out.setpoint.samples.resize(count);
  out.laser.samples.resize(count);
  st.plane_speeds.resize(count);
  if (config_.debug)
  {
    out.debug.samples.resize(count);
  }
  const bool speed_power = (config_.power_mode != "constant");
  const bool t2_identity = !st.adaptive && st.fir2.duration() == 0.0;
  const PathTimeline& timeline = st.plan.program.timeline;

  // One IGT solve; on failure the job is abandoned (done() is true, start() again to continue).
  auto solveOrAbandon = [&](const Eigen::Vector2d& x, const Eigen::Vector2d& guess, std::uint64_t n, double t_s,
                            const char* what) -> Eigen::Vector2d {
    try
    {
      return igt_->solve(optics_, x, guess);
    }
    catch (const NumericalError& e)
    {
      std::ostringstream msg;
      msg << "NC: job '" << st.job_name << "' sample " << n << " (t = " << t_s << " s): " << what << " " << pointText(x)
          << " is not reachable by the optics: " << e.what();
      state_.reset();
      throw NumericalError(msg.str());
    }
  };

  // The IGT of st.igt_point[0, count) into st.q_igt. A point equal to the previous one reuses its
  // solution (holds, the tail). Newton with the predictor: the distinct points in one block
  // (Igt::solveBlock; each sample's solution depends on its point only), the few it does not
  // accept by the scalar Newton from its last iterate. Without it: each warm-started from the
  // linear extrapolation 2·q_{n−1} − q_{n−2} of the previous solutions (O(q̈·Ts²) off).
  auto solveChunk = [&](std::size_t count_) {
    st.distinct.resize(count_);
    st.distinct_x.resize(count_);
    st.distinct_y.resize(count_);
    std::size_t m = 0;
    double previous_x = st.x_prev.x();
    double previous_y = st.x_prev.y();
    for (std::size_t i = 0; i < count_; ++i)
    {
      const double x = st.igt_point[i].x();
      const double y = st.igt_point[i].y();
      if (!(x == previous_x && y == previous_y))
      {
        previous_x = x;
        previous_y = y;
        st.distinct[m] = i;
        st.distinct_x[m] = x;
        st.distinct_y[m] = y;
        ++m;
      }
    }
    st.distinct_q.resize(m);
    st.distinct_ok.assign(m, 0);
    const bool block = !igt_->use_table && igt_->have_predictor;
    if (block && m > 0)
    {
      igt_->solveBlock(optics_, m, st.distinct_x.data(), st.distinct_y.data(), st.distinct_q.data(),
                       st.distinct_ok.data());
    }
    std::size_t d = 0;
    Eigen::Vector2d q_prev = st.q_prev;
    Eigen::Vector2d q_prev2 = st.q_prev2;
    for (std::size_t i = 0; i < count_; ++i)
    {
      Eigen::Vector2d q = q_prev;
      if (d < m && st.distinct[d] == i)
      {
        const std::uint64_t n = st.next + i;
        const double t_s = static_cast<double>(n) * ts;
        const Eigen::Vector2d x(st.distinct_x[d], st.distinct_y[d]);
        if (block)
        {
          q = st.distinct_ok[d] ? st.distinct_q[d] : solveOrAbandon(x, st.distinct_q[d], n, t_s, "path point");
        }
        else
        {
          q = solveOrAbandon(x, 2.0 * q_prev - q_prev2, n, t_s, "path point");
        }
        st.x_prev = x;
        ++d;
      }
      st.q_igt[i] = q;
      q_prev2 = q_prev;
      q_prev = q;
    }
  };

  // X_inter (and X_filt2, adaptive) of the whole chunk, then its IGT, then the sequential filters.
  st.x_inter.resize(count);
  st.igt_point.resize(count);
  st.q_igt.resize(count);
  if (st.adaptive)
  {
    st.filt2.resize(count);
  }
  for (std::size_t i = 0; i < count; ++i)
  {
    const double t_s = static_cast<double>(st.next + i) * ts;
    st.x_inter[i] = timeline.positionAt(t_s, st.path_cursor);
    if (st.adaptive)
    {
      st.filt2[i] = st.adaptive_fir.filtered(t_s, st.filt2_cursor);
      st.igt_point[i] = st.filt2[i].position;
    }
    else
    {
      st.igt_point[i] = st.x_inter[i];
    }
  }
  solveChunk(count);

  if (!st.adaptive)
  {
    // FIR T1, velocity saturation, FIR T2 (per axis, joint space), a chunk at a time
    // (BoxFilter::pushBlock: the same numbers as sample by sample).
    st.q_filt1.resize(count);
    st.q_filt1_dot.resize(count);
    st.s_and_rate.resize(count);
    st.filt2_average.resize(count);
    st.filt2_derivative.resize(count);
    st.fir1.pushBlock(st.q_igt.data(), count, st.q_filt1.data(), st.q_filt1_dot.data());
    for (std::size_t i = 0; i < count; ++i)
    {
      Eigen::Vector2d s;
      Eigen::Vector2d s_dot;
      st.limiter.step(st.q_filt1[i], st.q_filt1_dot[i], s, s_dot);
      st.s_and_rate[i] << s, s_dot;
    }
    // (the average of ṡ is not used; with T2 = 0 the average of s neither)
    st.fir2.pushBlock(st.s_and_rate.data(), count, st.filt2_average.data(), st.filt2_derivative.data(),
                      t2_identity ? 0 : 2);
    if (speed_power)
    {
      // the same filters on X_inter: the plane speed of the filtered path
      st.plane_average.resize(count);
      st.plane_average2.resize(count);
      st.plane_derivative.resize(count);
      st.plane_fir1.pushBlock(st.x_inter.data(), count, st.plane_average.data(), nullptr);
      st.plane_fir2.pushBlock(st.plane_average.data(), count, st.plane_average2.data(), st.plane_derivative.data(), 0);
    }
  }

  SetpointSample* const setpoints = out.setpoint.samples.data();
  if (!st.adaptive)
  {
    // The fixed filters: Q_filt2 and its derivatives as the filters give them.
    for (std::size_t i = 0; i < count; ++i)
    {
      SetpointSample& sp = setpoints[i];
      const Eigen::Vector4d& derivative = st.filt2_derivative[i];
      if (t2_identity)
      {
        sp.position = st.s_and_rate[i].head<2>();
        sp.velocity = st.s_and_rate[i].tail<2>();
      }
      else
      {
        sp.position = st.filt2_average[i].head<2>();
        sp.velocity = derivative.head<2>();
      }
      sp.acceleration = derivative.tail<2>();
      st.plane_speeds[i] = speed_power ? st.plane_derivative[i].norm() : 0.0;
    }
    if (config_.debug)
    {
      // Q_inter's backward differences need the solutions one by one (the same shift as below).
      for (std::size_t i = 0; i < count; ++i)
      {
        const Eigen::Vector2d q = st.q_igt[i];
        st.q_prev2 = st.q_prev;
        st.q_prev = q;
        NcDebugSample& dbg = out.debug.samples[i];
        dbg.x_inter = st.x_inter[i];
        dbg.q_inter = q;
        dbg.q_inter_velocity = (q - st.q_prev2) / ts;
        dbg.q_inter_acceleration = (q - 2.0 * st.q_prev2 + st.q_inter_prev2) / (ts * ts);
        st.q_inter_prev2 = st.q_prev2;
        st.inter_rate_fir1.push(dbg.q_inter_velocity);
        dbg.q_filt1 = st.q_filt1[i];
        dbg.q_filt1_velocity = st.q_filt1_dot[i];
        dbg.q_filt1_acceleration = st.inter_rate_fir1.derivative();
      }
    }
    else if (count > 0)
    {
      st.q_prev2 = count > 1 ? st.q_igt[count - 2] : st.q_prev;
      st.q_prev = st.q_igt[count - 1];
    }
  }
  else
  {
    // The adaptive filter: Q_filt2 is the IGT of X_filt2, its derivatives through J⁻¹.
    for (std::size_t i = 0; i < count; ++i)
    {
      const std::uint64_t n = st.next + i;
      const double t_s = static_cast<double>(n) * ts;
      const Eigen::Vector2d& x = st.x_inter[i];
      SetpointSample& sp = setpoints[i];
      const PlaneState& filt2 = st.filt2[i];
      const Eigen::Vector2d q = st.q_igt[i];
      st.q_prev2 = st.q_prev;
      st.q_prev = q;
      const Eigen::Matrix2d inverse_jacobian = optics_.jacobian(q).inverse();
      sp.position = q;
      sp.velocity = inverse_jacobian * filt2.velocity;
      sp.acceleration = inverse_jacobian * (filt2.acceleration - jacobianRateTimesVelocity(optics_, q, sp.velocity));
      st.plane_speeds[i] = filt2.velocity.norm();
      if (config_.debug)
      {
        NcDebugSample& dbg = out.debug.samples[i];
        const PlaneState filt1 = st.adaptive_fir.firstStage(t_s, st.filt1_cursor);
        dbg.x_inter = x;
        dbg.q_inter = solveOrAbandon(x, st.q_inter_prev, n, t_s, "debug point");
        dbg.q_inter_velocity = (dbg.q_inter - st.q_inter_prev) / ts;
        dbg.q_inter_acceleration = (dbg.q_inter - 2.0 * st.q_inter_prev + st.q_inter_prev2) / (ts * ts);
        st.q_inter_prev2 = st.q_inter_prev;
        st.q_inter_prev = dbg.q_inter;
        dbg.q_filt1 = solveOrAbandon(filt1.position, q, n, t_s, "debug point");
        const Eigen::Matrix2d filt1_inverse_jacobian = optics_.jacobian(dbg.q_filt1).inverse();
        dbg.q_filt1_velocity = filt1_inverse_jacobian * filt1.velocity;
        dbg.q_filt1_acceleration =
            filt1_inverse_jacobian *
            (filt1.acceleration - jacobianRateTimesVelocity(optics_, dbg.q_filt1, dbg.q_filt1_velocity));
      }
    }
  }

  if (config_.quantisation_bits > 0)
  {
    // XY2-100: an unsigned word over the mechanical range; the servo gets the nearest code.
    const double lower = optics_.geometry().joint_lower_rad;
    const double codes = std::ldexp(1.0, config_.quantisation_bits) - 1.0;
    const double lsb = (optics_.geometry().joint_upper_rad - lower) / codes;
    for (std::size_t i = 0; i < count; ++i)
    {
      for (int a = 0; a < 2; ++a)
      {
        double& position = setpoints[i].position[a];
        const double code = std::min(codes, std::max(0.0, std::round((position - lower) / lsb)));
        position = lower + code * lsb;
      }
    }
  }

  // Limits on Q_filt2 (reported; the adaptive filter and cap_speeds are built to respect them).
  {
    const double accel_limit = config_.max_joint_accel_radps2 * kLimitSlack;
    const double jerk_limit = config_.max_joint_jerk_radps3 * kLimitSlack;
    double max_accel[2] = {st.stats.max_accel_radps2[0], st.stats.max_accel_radps2[1]};
    double max_jerk[2] = {st.stats.max_jerk_radps3[0], st.stats.max_jerk_radps3[1]};
    double previous[2] = {st.accel_prev[0], st.accel_prev[1]};
    std::uint64_t over_accel_samples = 0;
    std::uint64_t over_jerk_samples = 0;
    for (std::size_t i = 0; i < count; ++i)
    {
      const Eigen::Vector2d& acceleration = setpoints[i].acceleration;
      bool over_accel = false;
      bool over_jerk = false;
      for (int a = 0; a < 2; ++a)
      {
        const double accel = std::abs(acceleration[a]);
        const double jerk = std::abs((acceleration[a] - previous[a]) / ts);
        previous[a] = acceleration[a];
        max_accel[a] = std::max(max_accel[a], accel);
        max_jerk[a] = std::max(max_jerk[a], jerk);
        over_accel = over_accel || accel > accel_limit;
        over_jerk = over_jerk || jerk > jerk_limit;
      }
      over_accel_samples += over_accel ? 1 : 0;
      over_jerk_samples += over_jerk ? 1 : 0;
    }
    for (int a = 0; a < 2; ++a)
    {
      st.stats.max_accel_radps2[a] = max_accel[a];
      st.stats.max_jerk_radps3[a] = max_jerk[a];
      st.accel_prev[a] = previous[a];
    }
    st.stats.samples_over_accel += over_accel_samples;
    st.stats.samples_over_jerk += over_jerk_samples;
  }

  if (st.predictor)
  {
    // The servo model run on the setpoint predicts the actual joints; their plane speed
    // replaces the filtered path's.
    if (out.setpoint.first_index == 0 && count > 0)
    {
      st.predictor->reset(out.setpoint.samples.front().position);
    }
    const JointChunk predicted = st.predictor->process(out.setpoint);
    for (std::size_t i = 0; i < count; ++i)
    {
      const JointSample& j = predicted.samples[i];
      st.plane_speeds[i] = (optics_.jacobian(j.position) * j.velocity).norm();
    }
  }

  // Laser: the gate on the command timeline, aligned with Q_filt2 by the delays.
  for (std::size_t i = 0; i < count; ++i)
  {
    const double command_s = static_cast<double>(st.next + i) * ts - st.plan.gate_shift_s;
    double power = st.plan.program.gate.powerAt(command_s, st.gate_cursor);
    if (speed_power && power > 0.0)
    {
      const double programmed = st.plan.program.gate.speedAt(command_s, st.gate_cursor);
      if (programmed > 0.0)  // a dwell is meant to stand still: full power
      {
        power *= std::min(1.0, std::max(config_.power_floor, st.plane_speeds[i] / programmed));
      }
    }
    out.laser.samples[i].power_w = power;
    st.stats.laser_on_samples += power > 0.0 ? 1 : 0;
  }
  st.next += count;
  return out;
}

bool NcInterpolator::done() const
{
  return !state_ || state_->next >= state_->plan.total_samples;
}

std::uint64_t NcInterpolator::totalSamples() const
{
  return state_ ? state_->plan.total_samples : 0;
}

double NcInterpolator::pathDuration() const
{
  return state_ ? state_->plan.pathDuration() : 0.0;
}

const NcStats& NcInterpolator::stats() const
{
  return state_ ? state_->stats : empty_stats_;
}

const NcProgram& NcInterpolator::program() const
{
  if (!state_)
  {
    throw std::logic_error("NcInterpolator::program() before start() (or after an abandoned job)");
  }
  return state_->plan.program;
}

const NcPlan& NcInterpolator::plan() const
{
  if (!state_)
  {
    throw std::logic_error("NcInterpolator::plan() before start() (or after an abandoned job)");
  }
  return state_->plan;
}
}  // namespace scanhead
