/// \file test_nc_interpolator.cpp
/// \brief The NC stage against the closed forms of SPEC §2 (NC §3.2–3.3), chunk invariance,
/// laser gating, configuration checks.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include "fixtures/polyline_fixture.hpp"
#include "scanhead/common/errors.hpp"
#include "scanhead/job/path_timeline.hpp"
#include "scanhead/nc/nc_interpolator.hpp"
#include "scanhead/optics/defect_catalog.hpp"
#include "scanhead/optics/optical_model.hpp"

#ifndef SCANHEAD_SOURCE_DIR
#error "SCANHEAD_SOURCE_DIR must be defined (the package root, for urdf/scanhead.urdf)"
#endif

using namespace scanhead;

namespace
{
const OpticalModel& nominalOptics()
{
  static const OpticalModel model(geometryFromUrdfFile(std::string(SCANHEAD_SOURCE_DIR) + "/urdf/scanhead.urdf"),
                                  OpticsConfig());
  return model;
}

using scanhead::test_support::line;

struct Streams
{
  std::vector<SetpointSample> setpoint;
  std::vector<LaserSample> laser;
  std::vector<NcDebugSample> debug;
};

/// The streams of the job \p nc was started on, in chunks of \p chunk samples.
Streams drain(NcInterpolator& nc, const NcConfig& config, std::size_t chunk)
{
  Streams s;
  std::uint64_t expected_first = 0;
  while (!nc.done())
  {
    NcOutput out = nc.process(chunk);
    EXPECT_EQ(out.setpoint.first_index, expected_first);
    EXPECT_EQ(out.laser.first_index, expected_first);
    EXPECT_EQ(out.setpoint.period_s, config.period_s);
    EXPECT_EQ(out.laser.period_s, config.period_s);
    EXPECT_EQ(out.laser.samples.size(), out.setpoint.samples.size());
    EXPECT_LE(out.setpoint.samples.size(), chunk);
    if (config.debug)
    {
      EXPECT_EQ(out.debug.first_index, expected_first);
      EXPECT_EQ(out.debug.period_s, config.period_s);
      EXPECT_EQ(out.debug.samples.size(), out.setpoint.samples.size());
    }
    else
    {
      EXPECT_TRUE(out.debug.samples.empty());
    }
    expected_first += out.setpoint.samples.size();
    s.setpoint.insert(s.setpoint.end(), out.setpoint.samples.begin(), out.setpoint.samples.end());
    s.laser.insert(s.laser.end(), out.laser.samples.begin(), out.laser.samples.end());
    s.debug.insert(s.debug.end(), out.debug.samples.begin(), out.debug.samples.end());
  }
  EXPECT_EQ(expected_first, nc.totalSamples());
  return s;
}

Streams run(const NcConfig& config, const Job& job, std::size_t chunk)
{
  NcInterpolator nc(config, nominalOptics());
  nc.start(job);
  return drain(nc, config, chunk);
}

/// Two 4 mm legs meeting at the origin with direction change gamma: in along +x, out at gamma.
Job cornerJob(double speed, const Eigen::Vector2d& out_direction)
{
  const double leg = 4e-3;
  Job job;
  job.name = "corner";
  job.polylines.push_back(
      line(PolylineType::Mark, speed, 100.0, {{-leg, 0.0}, {0.0, 0.0}, leg * out_direction.normalized()}));
  return job;
}

double distanceToSegment(const Eigen::Vector2d& p, const Eigen::Vector2d& a, const Eigen::Vector2d& b)
{
  const Eigen::Vector2d ab = b - a;
  const double len2 = ab.squaredNorm();
  const double u = len2 > 0.0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
  return (a + u * ab - p).norm();
}

struct CornerCase
{
  const char* name;
  double speed_mps;
  Eigen::Vector2d out_direction;
  double t1_s;
  double t2_s;
};
}  // namespace

// THE acceptance case (SPEC §2 closed forms, NC §3.2–3.3): a corner of direction change γ at
// speed V through the whole NC (exact timeline, IGT, FIR T1, saturation, FIR T2), Q_filt2 mapped
// back through the nominal optics. Measured:
//  * minimum tangential speed |J(q)·q̇| near the corner, theory V·|cos(γ/2)|; tolerance 1 %
//    (the closed form is for task-space filtering; the IGT nonlinearity is < 0.1 µm at these
//    speeds, SPEC §2.3, and the Jacobian is exact forward-mode);
//  * contour error = min distance from the commanded corner to the polyline of setpoint spots,
//    theory V·(T2² + 3·T1²)/(12·T1)·|sin(γ/2)|; tolerance 2 % (chords of 20 µm at 2 m/s on a
//    ~0.5 mm radius sag by < 1e-10 m; the linear interpolation of the samples across the corner
//    moves the filtered tip by ≲ V·Ts²/T1 ≈ 1 µm at worst).
TEST(NcInterpolator, CornerSpeedAndContourErrorMatchClosedForms)
{
  const std::vector<CornerCase> cases = {
      {"V=2 gamma=53.13", 2.0, Eigen::Vector2d(3.0, 4.0), 260e-6, 125e-6},
      {"V=2 gamma=108.43", 2.0, Eigen::Vector2d(-1.0, 3.0), 260e-6, 125e-6},
      {"V=1 gamma=90", 1.0, Eigen::Vector2d(0.0, 1.0), 260e-6, 125e-6},
      {"V=2 gamma=90 T1=400 T2=200", 2.0, Eigen::Vector2d(0.0, 1.0), 400e-6, 200e-6},
      {"V=2 gamma=53.13 T1=123.4 T2=57.3", 2.0, Eigen::Vector2d(3.0, 4.0), 123.4e-6, 57.3e-6},
  };
  const OpticalModel& optics = nominalOptics();
  for (const CornerCase& c : cases)
  {
    NcConfig config;
    config.fir_t1_s = c.t1_s;
    config.fir_t2_s = c.t2_s;
    const Job job = cornerJob(c.speed_mps, c.out_direction);
    const Streams s = run(config, job, 1000);
    const double gamma = std::atan2(c.out_direction.y(), c.out_direction.x());
    const double t_corner = 4e-3 / c.speed_mps;
    const double delay = config.filterDelay();
    double v_min = 1e300;
    double e_c = 1e300;
    Eigen::Vector2d prev_spot = optics.spot(s.setpoint.front().position);
    for (std::size_t n = 0; n < s.setpoint.size(); ++n)
    {
      const double t = static_cast<double>(n) * config.period_s;
      const SetpointSample& sp = s.setpoint[n];
      const Eigen::Vector2d spot = optics.spot(sp.position);
      if (std::abs(t - delay - t_corner) <= c.t1_s + c.t2_s)
      {
        v_min = std::min(v_min, (optics.jacobian(sp.position) * sp.velocity).norm());
      }
      if (n > 0)
      {
        e_c = std::min(e_c, distanceToSegment(Eigen::Vector2d::Zero(), prev_spot, spot));
      }
      prev_spot = spot;
    }
    const double v_theory = c.speed_mps * std::abs(std::cos(gamma / 2));
    const double t1 = c.t1_s;
    const double t2 = c.t2_s;
    const double e_theory = c.speed_mps * (t2 * t2 + 3 * t1 * t1) / (12 * t1) * std::abs(std::sin(gamma / 2));
    std::printf(
        "[ corner ] %-34s gamma %7.3f deg: Vmin %8.2f mm/s (theory %8.2f, %+.3f %%), "
        "e_c %7.3f um (theory %7.3f, %+.3f %%)\n",
        c.name, gamma * 180 / M_PI, v_min * 1e3, v_theory * 1e3, 100 * (v_min / v_theory - 1), e_c * 1e6,
        e_theory * 1e6, 100 * (e_c / e_theory - 1));
    EXPECT_NEAR(v_min, v_theory, 0.01 * v_theory) << c.name;
    EXPECT_NEAR(e_c, e_theory, 0.02 * e_theory) << c.name;
    // far from the corner the spot moves at the programmed speed (0.1 %: IGT nonlinearity only)
    const std::size_t mid_leg = static_cast<std::size_t>((t_corner / 2 + delay) / config.period_s);
    const SetpointSample& sp = s.setpoint[mid_leg];
    EXPECT_NEAR((optics.jacobian(sp.position) * sp.velocity).norm(), c.speed_mps, 1e-3 * c.speed_mps) << c.name;
  }
}

// The machine starts at rest at the first point and ends at rest at the last (tail held).
TEST(NcInterpolator, StartsAndEndsAtRest)
{
  NcConfig config;
  const Job job = cornerJob(2.0, Eigen::Vector2d(0.0, 1.0));
  const Streams s = run(config, job, 1000);
  const OpticalModel& optics = nominalOptics();
  const Eigen::Vector2d q0 = optics.inverse(Eigen::Vector2d(-4e-3, 0.0));
  const Eigen::Vector2d q_end = optics.inverse(Eigen::Vector2d(0.0, 4e-3));
  // 1e-15 rad: the taps sum to 1 within rounding
  EXPECT_LT((s.setpoint.front().position - q0).norm(), 1e-15);
  EXPECT_EQ(s.setpoint.front().velocity, Eigen::Vector2d::Zero());
  EXPECT_EQ(s.setpoint.front().acceleration, Eigen::Vector2d::Zero());
  // Newton tolerance 1e-12 m / 1.4 m/rad ≈ 1e-12 rad on each solution
  EXPECT_LT((s.setpoint.back().position - q_end).norm(), 2e-12);
  EXPECT_EQ(s.setpoint.back().velocity, Eigen::Vector2d::Zero());
  EXPECT_EQ(s.setpoint.back().acceleration, Eigen::Vector2d::Zero());
  // total = ceil((path + T1 + T2 + tail)/Ts) + 1
  const double path = 8e-3 / 2.0;
  const double end = path + config.fir_t1_s + config.fir_t2_s + config.tail_s;
  EXPECT_EQ(s.setpoint.size(), static_cast<std::size_t>(std::llround(std::ceil(end / config.period_s - 1e-9))) + 1);
}

// The velocity and acceleration outputs are the derivatives of the position output. Checked by
// the trapezoid rule between consecutive samples, with its error bounds as tolerances:
//  * Δposition vs Ts·(v_n + v_{n−1})/2: error ≤ Ts³·max|jerk|/12, jerk ≤ max|a|/T2 (ramps of T2)
//    — tolerance twice that;
//  * Δvelocity vs Ts·(a_n + a_{n−1})/2: kinks of a inside a period give ≤ Ts²·|jerk|/8, and the
//    linear interpolation of Q_filt1's velocity across its own kinks (acceleration step ≤ max|a|
//    inside a period) ≤ Ts²·max|a|/(4·T2): tolerance 0.5·Ts²·max|a|/T2 (bound 0.375).
TEST(NcInterpolator, VelocityAndAccelerationAreConsistentDerivatives)
{
  NcConfig config;
  config.fir_t1_s = 263.7e-6;  // kinks of Q_filt1's velocity fall between samples
  config.fir_t2_s = 123.4e-6;
  Job job = cornerJob(2.0, Eigen::Vector2d(-1.0, 3.0));
  job.polylines.push_back(line(PolylineType::Mark, 1.0, 50.0, {{5e-3, 5e-3}, {6e-3, 2e-3}, {4e-3, 3e-3}}));
  const Streams s = run(config, job, 1000);
  const double ts = config.period_s;
  double a_max = 0.0;
  for (const auto& sp : s.setpoint)
  {
    a_max = std::max(a_max, sp.acceleration.cwiseAbs().maxCoeff());
  }
  ASSERT_GT(a_max, 1000.0);
  const double jerk_max = a_max / config.fir_t2_s;
  double worst_pos = 0.0;
  double worst_vel = 0.0;
  for (std::size_t n = 1; n < s.setpoint.size(); ++n)
  {
    const SetpointSample& a = s.setpoint[n - 1];
    const SetpointSample& b = s.setpoint[n];
    worst_pos =
        std::max(worst_pos, (b.position - a.position - 0.5 * ts * (a.velocity + b.velocity)).cwiseAbs().maxCoeff());
    worst_vel = std::max(
        worst_vel, (b.velocity - a.velocity - 0.5 * ts * (a.acceleration + b.acceleration)).cwiseAbs().maxCoeff());
  }
  std::printf(
      "[ deriv  ] max |a| %.1f rad/s^2: position residual %.3g rad (tolerance %.3g), velocity residual "
      "%.3g rad/s (tolerance %.3g)\n",
      a_max, worst_pos, 2.0 * ts * ts * ts * jerk_max / 12, worst_vel, 0.5 * ts * ts * a_max / config.fir_t2_s);
  EXPECT_LT(worst_pos, 2.0 * ts * ts * ts * jerk_max / 12);
  EXPECT_LT(worst_vel, 0.5 * ts * ts * a_max / config.fir_t2_s);
}

namespace
{
/// Three MARK polylines at different powers (one with corners), an implicit jump, an explicit
/// jump polyline, a contiguous mark at another speed.
Job laserJob()
{
  Job job;
  job.name = "laser";
  job.polylines.push_back(line(PolylineType::Mark, 1.0, 100.0, {{0.0, 0.0}, {2.345e-3, 0.0}, {2.345e-3, 1.1e-3}}));
  job.polylines.push_back(line(PolylineType::Mark, 0.8, 200.0, {{5e-3, 5e-3}, {5e-3, 7.777e-3}}));
  job.polylines.push_back(line(PolylineType::Jump, 5.0, 0.0, {{5e-3, 7.777e-3}, {-3e-3, -2e-3}}));
  job.polylines.push_back(line(PolylineType::Mark, 1.7, 300.0, {{-3e-3, -2e-3}, {-1e-3, -2.5e-3}, {0.0, 0.0}}));
  return job;
}
}  // namespace

// Laser gate aligned with Q_filt2: per mark polyline, the laser-on samples number the mark time
// / Ts within ±1 (a half-open interval of duration D holds floor or ceil of D/Ts sample
// instants), and the first one is the first n with n·Ts − (T1+T2)/2 >= the mark's start time.
TEST(NcInterpolator, LaserGateMatchesMarkTimesShiftedByFilterDelay)
{
  NcConfig config;
  config.fir_t1_s = 263.7e-6;
  const Job job = laserJob();
  const Streams s = run(config, job, 1000);
  const PathTimeline tl(job, config.implicit_jump_speed_mps);
  const double ts = config.period_s;
  const double delay = config.filterDelay();
  for (std::size_t p : {0u, 1u, 3u})
  {
    double mark_start = -1.0;
    double mark_time = 0.0;
    for (const PathSegment& seg : tl.segments())
    {
      if (seg.polyline == p && seg.mark)
      {
        if (mark_start < 0.0)
        {
          mark_start = seg.t_start_s;
        }
        mark_time += seg.duration_s;
      }
    }
    const double power = job.polylines[p].power_w;
    std::size_t on = 0;
    std::size_t first = s.laser.size();
    for (std::size_t n = 0; n < s.laser.size(); ++n)
    {
      if (s.laser[n].power_w == power)
      {
        ++on;
        first = std::min(first, n);
      }
    }
    std::size_t expected_first = 0;
    while (static_cast<double>(expected_first) * ts - delay < mark_start)
    {
      ++expected_first;
    }
    EXPECT_NEAR(static_cast<double>(on), mark_time / ts, 1.0) << "polyline " << p;
    EXPECT_EQ(first, expected_first) << "polyline " << p;
    // the on-samples are contiguous
    for (std::size_t n = first; n < first + on; ++n)
    {
      EXPECT_EQ(s.laser[n].power_w, power) << "polyline " << p << " sample " << n;
    }
  }
  // off during jumps, before the start and after the end
  EXPECT_EQ(s.laser.front().power_w, 0.0);
  EXPECT_EQ(s.laser.back().power_w, 0.0);
  std::size_t total_on = 0;
  for (const auto& l : s.laser)
  {
    total_on += (l.power_w > 0.0);
  }
  std::size_t per_polyline = 0;
  for (const auto& l : s.laser)
  {
    per_polyline += (l.power_w == 100.0 || l.power_w == 200.0 || l.power_w == 300.0);
  }
  EXPECT_EQ(total_on, per_polyline);
}

// Chunks of 1, 7 and 1000 samples give bit-identical setpoint, laser and debug streams.
TEST(NcInterpolator, ChunkSizeDoesNotChangeOutput)
{
  NcConfig config;
  config.debug = true;
  config.fir_t2_s = 123.4e-6;
  const Job job = laserJob();
  const Streams ref = run(config, job, 1000);
  for (std::size_t chunk : {1u, 7u})
  {
    const Streams s = run(config, job, chunk);
    ASSERT_EQ(s.setpoint.size(), ref.setpoint.size());
    ASSERT_EQ(s.debug.size(), ref.debug.size());
    for (std::size_t n = 0; n < ref.setpoint.size(); ++n)
    {
      ASSERT_EQ(s.setpoint[n].position, ref.setpoint[n].position) << "chunk " << chunk << " n " << n;
      ASSERT_EQ(s.setpoint[n].velocity, ref.setpoint[n].velocity) << "chunk " << chunk << " n " << n;
      ASSERT_EQ(s.setpoint[n].acceleration, ref.setpoint[n].acceleration) << "chunk " << chunk << " n " << n;
      ASSERT_EQ(s.laser[n].power_w, ref.laser[n].power_w) << "chunk " << chunk << " n " << n;
      ASSERT_EQ(s.debug[n].x_inter, ref.debug[n].x_inter) << "chunk " << chunk << " n " << n;
      ASSERT_EQ(s.debug[n].q_inter, ref.debug[n].q_inter) << "chunk " << chunk << " n " << n;
      ASSERT_EQ(s.debug[n].q_filt1, ref.debug[n].q_filt1) << "chunk " << chunk << " n " << n;
    }
  }
  // restarting resets everything: a second start gives the same stream again
  NcInterpolator nc(config, nominalOptics());
  nc.start(job);
  (void)nc.process(12345);
  nc.start(job);
  const NcOutput again = nc.process(1000);
  EXPECT_EQ(again.setpoint.first_index, 0u);
  for (std::size_t n = 0; n < again.setpoint.samples.size(); ++n)
  {
    ASSERT_EQ(again.setpoint.samples[n].position, ref.setpoint[n].position);
  }
}

// The node graph's NC node starts the same NC again for each job (its IGT tables are built once, ~2.7 ms): a job after
// another one, and after a start that failed, gives the streams of a new NC, bit for bit.
TEST(NcInterpolator, StartedAgainForAnotherJobGivesTheStreamsOfANewOne)
{
  NcConfig config;
  config.debug = true;
  const Job second = cornerJob(2.0, Eigen::Vector2d(-0.6, 0.8));
  NcInterpolator fresh_nc(config, nominalOptics());
  fresh_nc.start(second);
  const Streams fresh = drain(fresh_nc, config, 1000);
  NcInterpolator nc(config, nominalOptics());
  nc.start(laserJob());
  ASSERT_FALSE(drain(nc, config, 777).setpoint.empty());  // the whole first job
  Job unreachable = laserJob();
  unreachable.polylines[3].points[1] = Eigen::Vector2d(0.3, -2.5e-3);
  EXPECT_THROW(nc.start(unreachable), NumericalError);
  nc.start(second);
  const Streams again = drain(nc, config, 1000);
  ASSERT_EQ(again.setpoint.size(), fresh.setpoint.size());
  ASSERT_EQ(again.debug.size(), fresh.debug.size());
  for (std::size_t n = 0; n < fresh.setpoint.size(); ++n)
  {
    ASSERT_EQ(again.setpoint[n].position, fresh.setpoint[n].position) << n;
    ASSERT_EQ(again.setpoint[n].velocity, fresh.setpoint[n].velocity) << n;
    ASSERT_EQ(again.setpoint[n].acceleration, fresh.setpoint[n].acceleration) << n;
    ASSERT_EQ(again.laser[n].power_w, fresh.laser[n].power_w) << n;
    ASSERT_EQ(again.debug[n].q_inter, fresh.debug[n].q_inter) << n;
    ASSERT_EQ(again.debug[n].q_filt1, fresh.debug[n].q_filt1) << n;
  }
  EXPECT_EQ(nc.stats().max_accel_radps2, fresh_nc.stats().max_accel_radps2);  // the job's own statistics
  EXPECT_EQ(nc.stats().laser_on_samples, fresh_nc.stats().laser_on_samples);
}

// The Newton IGT (a block: bicubic-table start, one simplified Newton step, both residuals traced)
// converges on every sample: |h(Q_inter) − X_inter| <= newton_tolerance_m (1e-12 m), checked with
// the scalar ray trace, over a job crossing the whole field (corners included, marks at 1 m/s,
// jumps at 5 and 20 m/s) on the nominal machine, OPT table 2's defects and random defect sets;
// its solution agrees with OpticalModel::inverse (the scalar Newton) to within the same bound on
// the plane, and chunks of 1, 7 and 1000 samples give bit-identical streams.
TEST(NcInterpolator, BlockIgtConvergesOnEverySampleOverTheFieldWithDefects)
{
  const OpticalGeometry nominal = geometryFromUrdfFile(std::string(SCANHEAD_SOURCE_DIR) + "/urdf/scanhead.urdf");
  const double h = 0.17;  // inside the 0.175 m field
  Job job;
  job.name = "field";
  job.polylines.push_back(line(PolylineType::Jump, 20.0, 0.0, {{-h, -h}, {h, h}}));
  job.polylines.push_back(line(PolylineType::Mark, 1.0, 100.0, {{h, h}, {h, h - 2e-3}, {h - 3e-3, h - 1e-3}}));
  job.polylines.push_back(line(PolylineType::Jump, 5.0, 0.0, {{h - 3e-3, h - 1e-3}, {-h, h}, {h, -h}}));
  job.polylines.push_back(line(PolylineType::Mark, 1.0, 100.0, {{h, -h}, {h - 2e-3, -h + 1e-3}, {0.0, 0.0}}));
  const std::vector<std::pair<std::string, DefectSet>> machines = {
      {"nominal", DefectSet()}, {"OPT table 2", optTable2DefectSet()}, {"random seed 7", randomDefectSet(7)}};
  for (const auto& machine : machines)
  {
    const OpticalModel optics(applyDefects(nominal, machine.second), OpticsConfig());
    NcConfig config;
    config.debug = true;
    std::vector<NcDebugSample> ref;
    for (std::size_t chunk : {1000u, 1u, 7u})
    {
      NcInterpolator nc(config, optics);
      nc.start(job);
      std::vector<NcDebugSample> debug;
      while (!nc.done())
      {
        const NcOutput out = nc.process(chunk);
        debug.insert(debug.end(), out.debug.samples.begin(), out.debug.samples.end());
      }
      if (chunk == 1000u)
      {
        ref = debug;
        continue;
      }
      ASSERT_EQ(debug.size(), ref.size());
      for (std::size_t n = 0; n < ref.size(); ++n)
      {
        ASSERT_EQ(debug[n].q_inter, ref[n].q_inter) << machine.first << ", chunk " << chunk << ", n " << n;
      }
    }
    double worst_residual = 0.0;
    double worst_vs_scalar = 0.0;
    for (std::size_t n = 0; n < ref.size(); ++n)
    {
      const Eigen::Vector2d& x = ref[n].x_inter;
      const Eigen::Vector2d& q = ref[n].q_inter;
      worst_residual = std::max(worst_residual, (optics.spot(q) - x).norm());
      if (n % 10 == 0)
      {
        const Eigen::Vector2d q_scalar = optics.inverse(x, Eigen::Vector2d::Zero());
        worst_vs_scalar = std::max(worst_vs_scalar, (optics.spot(q) - optics.spot(q_scalar)).norm());
      }
    }
    std::printf("[ info ] %s: %zu samples, max |h(q) - x| = %.3g m, max |h(q) - h(q_scalar)| = %.3g m\n",
                machine.first.c_str(), ref.size(), worst_residual, worst_vs_scalar);
    EXPECT_LE(worst_residual, OpticsConfig().newton_tolerance_m) << machine.first;
    EXPECT_LE(worst_vs_scalar, 2.0 * OpticsConfig().newton_tolerance_m) << machine.first;
  }
}

// The debug stream: X_inter is the timeline sampled at n·Ts, Q_inter its inverse (spot within
// the Newton tolerance, 1e-12 m, plus rounding), Q_filt1 the FIR T1 output.
TEST(NcInterpolator, DebugStreamIsTheSampledPathAndItsInverse)
{
  NcConfig config;
  config.debug = true;
  const Job job = laserJob();
  const Streams s = run(config, job, 1000);
  const PathTimeline tl(job, config.implicit_jump_speed_mps);
  PathTimeline::Cursor c;
  for (std::size_t n = 0; n < s.debug.size(); n += 13)
  {
    EXPECT_EQ(s.debug[n].x_inter, tl.positionAt(static_cast<double>(n) * config.period_s, c));
    EXPECT_LT((nominalOptics().spot(s.debug[n].q_inter) - s.debug[n].x_inter).norm(), 2e-12);
  }
}

// Velocity saturation: with a low limit the joint speed of Q_filt2 never exceeds it (the box T2
// is an average of limited velocities), and the path still arrives (tail long enough).
TEST(NcInterpolator, VelocitySaturationBoundsJointSpeed)
{
  NcConfig config;
  config.max_joint_speed_radps = 0.5;  // 2 m/s ≈ 1.4 rad/s at the mirrors: saturates
  config.tail_s = 20e-3;
  const Job job = cornerJob(2.0, Eigen::Vector2d(0.0, 1.0));
  const Streams s = run(config, job, 1000);
  double v_max = 0.0;
  for (const auto& sp : s.setpoint)
  {
    v_max = std::max(v_max, sp.velocity.cwiseAbs().maxCoeff());
  }
  EXPECT_LE(v_max, 0.5 * (1 + 1e-12));
  EXPECT_GT(v_max, 0.5 * (1 - 1e-12));  // and it was reached
  const Eigen::Vector2d q_end = nominalOptics().inverse(Eigen::Vector2d(0.0, 4e-3));
  EXPECT_LT((s.setpoint.back().position - q_end).norm(), 2e-12);
}

TEST(NcConfig, ValidateNamesFieldAndValue)
{
  auto message = [](NcConfig c) -> std::string {
    try
    {
      c.validate();
    }
    catch (const ConfigError& e)
    {
      return e.what();
    }
    return "";
  };
  EXPECT_EQ(message(NcConfig()), "");
  NcConfig c;
  c.fir_t1_s = -1e-5;
  EXPECT_EQ(message(c), "nc.fir_t1_s must be >= 0 (got -1e-05)");
  c = NcConfig();
  c.fir_t1_s = 0.0;
  c.fir_t2_s = 0.0;
  EXPECT_EQ(message(c), "");  // T = 0: identity filters allowed
  c.fir_t2_s = std::nan("");
  EXPECT_EQ(message(c), "nc.fir_t2_s must be >= 0 (got nan)");
  c = NcConfig();
  c.period_s = 0.0;
  EXPECT_EQ(message(c), "nc.period_s must be > 0 (got 0)");
  c = NcConfig();
  c.max_joint_speed_radps = -3.0;
  EXPECT_EQ(message(c), "nc.max_joint_speed_radps must be > 0 (got -3)");
  c = NcConfig();
  c.implicit_jump_speed_mps = std::nan("");
  EXPECT_EQ(message(c), "nc.implicit_jump_speed_mps must be > 0 (got nan)");
  c = NcConfig();
  c.tail_s = -1.0;
  EXPECT_EQ(message(c), "nc.tail_s must be >= 0 (got -1)");
  c = NcConfig();
  c.fir_t1_s = INFINITY;
  EXPECT_EQ(message(c), "nc.fir_t1_s must be finite (got inf)");
  c = NcConfig();
  c.period_s = -1e-5;
  EXPECT_THROW(NcInterpolator(c, nominalOptics()), ConfigError);
}

// Identity filters (T1 = T2 = 0) are allowed: Q_filt2 = Q_inter.
TEST(NcInterpolator, ZeroDurationFiltersAreIdentity)
{
  NcConfig config;
  config.fir_t1_s = 0.0;
  config.fir_t2_s = 0.0;
  config.debug = true;
  const Streams s = run(config, laserJob(), 1000);
  for (std::size_t n = 0; n < s.setpoint.size(); ++n)
  {
    ASSERT_EQ(s.setpoint[n].position, s.debug[n].q_inter) << n;
  }
}

// A job point outside the reachable field: start() throws NumericalError naming it.
TEST(NcInterpolator, UnreachablePointThrowsNamingIt)
{
  Job job = laserJob();
  job.polylines[3].points[1] = Eigen::Vector2d(0.3, -2.5e-3);
  NcInterpolator nc(NcConfig(), nominalOptics());
  try
  {
    nc.start(job);
    FAIL() << "no exception";
  }
  catch (const NumericalError& e)
  {
    const std::string what = e.what();
    EXPECT_NE(what.find("polyline 3 point 1"), std::string::npos) << what;
    EXPECT_NE(what.find("(0.3, -0.0025) m"), std::string::npos) << what;
  }
  EXPECT_TRUE(nc.done());  // no half-started job
  job.polylines.clear();
  EXPECT_THROW(nc.start(job), InputError);
}
