// The whole chain in process: the NC paper's corner figures, chunk invariance, energy balance.
#include <gtest/gtest.h>

#include <cmath>

#include "fixtures/chain_fixture.hpp"
#include "scanhead/chain/batch_chain.hpp"
#include "scanhead/chain/config_io.hpp"
#include "scanhead/job/formats/job_io.hpp"
#include "scanhead/job/job_files.hpp"
#include "scanhead/metrics/metrics_report.hpp"

using namespace scanhead;
using scanhead::test_support::ChainRun;
using scanhead::test_support::kConfig;
using scanhead::test_support::runJob;

namespace
{
struct CornerCase
{
  double speed_mps, angle_deg, t1_s, t2_s;
};
}  // namespace

// NC §3.2–3.3: Vf_min = V|cos(γ/2)| (1 %), e_c = V(T2² + 3T1²)/(12 T1)|sin(γ/2)| (2 %), on the
// setpoint path (Q_filt2 through the direct optical model), as the acceptance asks.
TEST(BatchChain, CornerMatchesClosedForms)
{
  const std::vector<CornerCase> cases = {{2.0, 53.13, 260e-6, 125e-6}, {2.0, 108.43, 260e-6, 125e-6},
                                         {1.0, 90.0, 260e-6, 125e-6},  {1.5, 60.0, 400e-6, 200e-6},
                                         {3.0, 135.0, 200e-6, 200e-6}, {0.5, 30.0, 137e-6, 61e-6}};
  for (const CornerCase& c : cases)
  {
    char spec[128];
    std::snprintf(spec, sizeof spec, "corner:speed=%g,angle=%g,leg=0.004", c.speed_mps, c.angle_deg);
    const ChainRun run =
        runJob(spec, {"nc.fir_t1_s=" + std::to_string(c.t1_s), "nc.fir_t2_s=" + std::to_string(c.t2_s)});
    ASSERT_EQ(run.metrics.corners.size(), 1u) << spec;
    const CornerReport& r = run.metrics.corners[0];
    const double gamma = c.angle_deg * M_PI / 180.0;
    const double t1 = std::max(c.t1_s, c.t2_s), t2 = std::min(c.t1_s, c.t2_s);
    const double v_min = c.speed_mps * std::fabs(std::cos(gamma / 2));
    const double e_c = c.speed_mps * (t2 * t2 + 3 * t1 * t1) / (12 * t1) * std::fabs(std::sin(gamma / 2));
    EXPECT_NEAR(r.theory.min_speed_mps, v_min, 1e-12 * c.speed_mps) << spec;
    EXPECT_NEAR(r.theory.max_contour_error_m, e_c, 1e-15) << spec;
    EXPECT_NEAR(r.setpoint.min_speed_mps, v_min, 0.01 * v_min) << spec;
    EXPECT_NEAR(r.setpoint.max_contour_error_m, e_c, 0.02 * e_c) << spec;
    // The servo smooths the corner further (lower minimum speed). On the NC paper's corners (2 m/s,
    // 53.13° and 108.43°) the default cascade model (voltage feedforward on) keeps the actual path
    // close to the filtered setpoint (the NC paper's bench measured 62 and 109 µm): actual contour error
    // within 15 % of the setpoint's, measured −13.1 % and −10.9 % with the dry friction fitted to THESIS
    // Tableau 3.1 (issue 15; the earlier guessed friction, Tc 2.5× larger, gave −6.2 % and −0.8 %, inside the
    // 10 % this test had: the axis that starts from rest at the corner lags less with less friction).
    // The other cases stay of the same order (1 m/s 90°: −5.5 %; 0.5 m/s 30°: 4.71 µm vs 4.75 µm).
    EXPECT_LT(r.actual.min_speed_mps, r.setpoint.min_speed_mps) << spec;
    if (c.speed_mps == 2.0)
    {
      EXPECT_NEAR(r.actual.max_contour_error_m, r.setpoint.max_contour_error_m, 0.15 * r.setpoint.max_contour_error_m)
          << spec;
    }
    EXPECT_GT(r.actual.max_contour_error_m, 0.5 * r.setpoint.max_contour_error_m) << spec;
    EXPECT_LT(r.actual.max_contour_error_m, 3.0 * r.setpoint.max_contour_error_m) << spec;
    std::printf(
        "%-36s setpoint %.1f mm/s (theory %.1f, %+.3f %%), e_c %.2f um (theory %.2f, %+.3f %%); actual %.1f mm/s, %.2f "
        "um\n",
        spec, r.setpoint.min_speed_mps * 1e3, v_min * 1e3, 100 * (r.setpoint.min_speed_mps / v_min - 1),
        r.setpoint.max_contour_error_m * 1e6, e_c * 1e6, 100 * (r.setpoint.max_contour_error_m / e_c - 1),
        r.actual.min_speed_mps * 1e3, r.actual.max_contour_error_m * 1e6);
  }
}

// The published case (NC §3.3): 1789 mm/s / 62 µm and 1170 mm/s / 114 µm. The paper rounds to
// the µm and the angles to 0.01°, so: speeds within 0.1 %, contour errors within 1.5 % (62.6 → "62").
TEST(BatchChain, PublishedFigures)
{
  const ChainRun a = runJob("corner:speed=2,angle=53.13", {});
  const ChainRun b = runJob("corner:speed=2,angle=108.43", {});
  for (const CornerPathStats& s : {a.metrics.corners[0].theory, a.metrics.corners[0].setpoint})
  {
    EXPECT_NEAR(s.min_speed_mps, 1.789, 0.001 * 1.789);
    EXPECT_NEAR(s.max_contour_error_m, 62e-6, 0.015 * 62e-6);
  }
  for (const CornerPathStats& s : {b.metrics.corners[0].theory, b.metrics.corners[0].setpoint})
  {
    EXPECT_NEAR(s.min_speed_mps, 1.170, 0.001 * 1.170);
    EXPECT_NEAR(s.max_contour_error_m, 114e-6, 0.015 * 114e-6);
  }
}

// Chunks of 1, 7 and 1000 samples: bit-identical metrics and energy map.
TEST(BatchChain, ChunkingDoesNotChangeResults)
{
  const ChainRun ref = runJob("corner", {"stream.chunk_samples=1000"});
  for (const char* chunk : {"1", "7"})
  {
    const ChainRun other = runJob("corner", {std::string("stream.chunk_samples=") + chunk});
    EXPECT_EQ(metricsToYaml(other.metrics), metricsToYaml(ref.metrics)) << chunk;
    EXPECT_TRUE(other.map == ref.map) << "energy map differs with chunks of " << chunk;
  }
}

// One thread or two (NC → servo → optics pipelined with the energy stage, trackers beside the map):
// bit-identical metrics and map, whatever the chunking.
TEST(BatchChain, ThreadsDoNotChangeResults)
{
  // The last with a 1 MiB map that spills (its batches pinned, or added serially where they cannot be): the same
  // tiles spilled too (metrics.yaml).
  for (const char* cache : {"268435456", "1048576"})
    for (const char* job : {"corner", "hatch:size=0.002,spacing=0.0002"})
    {
      const std::string cache_setting = std::string("energy.tile_cache_bytes=") + cache;
      const ChainRun one = runJob(job, {"stream.threads=1", cache_setting});
      for (const char* chunk : {"1000", "7"})
      {
        const ChainRun two =
            runJob(job, {"stream.threads=2", std::string("stream.chunk_samples=") + chunk, cache_setting});
        EXPECT_EQ(metricsToYaml(two.metrics), metricsToYaml(one.metrics)) << job << ", chunks of " << chunk;
        EXPECT_TRUE(two.map == one.map) << job << ": energy map differs on two threads, chunks of " << chunk;
      }
    }
}

// An error on the consumer's side (here the progress callback) stops both threads and reaches the
// caller: no hang, no thread left running, and the chain runs the next job normally.
TEST(BatchChain, ConsumerErrorStopsThePipeline)
{
  for (const char* threads : {"1", "2"})
  {
    const ChainConfig config =
        loadChainConfig(kConfig, {std::string("stream.threads=") + threads, "stream.chunk_samples=100"});
    const OpticalModel optics = loadOpticalModel(config.optics);
    const Job job = loadJob("corner", config.cam);
    BatchChain chain(config, optics);
    int calls = 0;
    EXPECT_THROW(chain.run(job,
                           [&](std::uint64_t, std::uint64_t) {
                             if (++calls == 3)
                               throw std::runtime_error("stop");
                           }),
                 std::runtime_error)
        << threads;
    EXPECT_EQ(calls, 3) << threads;
    const RunMetrics again = chain.run(job);
    EXPECT_EQ(metricsToYaml(again), metricsToYaml(runJob("corner", {}).metrics)) << threads;
  }
}

// The bounded-memory paths of the energy stage do not depend on the chunking either: the track
// thinned to every 8th laser-on sample (cap 100), a 1 MiB tile cache that spills, the nearest-path
// contour error switched off by its cap; and thinning keeps the straight-track level within 2 %.
TEST(BatchChain, BoundedMemoryPathsAreChunkInvariant)
{
  const std::vector<std::string> bounded = {"energy.track_max_samples=100", "energy.tile_cache_bytes=1048576",
                                            "energy.contour_max_samples=100", "energy.pixel_m=2e-6"};
  auto with = [&](const char* chunk) {
    std::vector<std::string> o = bounded;
    o.push_back(std::string("stream.chunk_samples=") + chunk);
    return runJob("corner", o);
  };
  const ChainRun ref = with("1000");
  EXPECT_GT(ref.metrics.track_stride, 1u);
  EXPECT_GT(ref.metrics.map_tiles_spilled, 0u);
  EXPECT_FALSE(ref.metrics.quality.nearest_measured);
  for (const char* chunk : {"1", "7"})
  {
    const ChainRun other = with(chunk);
    EXPECT_EQ(metricsToYaml(other.metrics), metricsToYaml(ref.metrics)) << chunk;
    EXPECT_TRUE(other.map == ref.map) << "energy map differs with chunks of " << chunk;
  }
  const ChainRun full = runJob("corner", {"energy.pixel_m=2e-6"});
  EXPECT_EQ(full.metrics.track_stride, 1u);
  EXPECT_NEAR(ref.metrics.track_median_jpm2, full.metrics.track_median_jpm2, 0.02 * full.metrics.track_median_jpm2);
  EXPECT_TRUE(full.map == ref.map) << "spilling changed the map";
}

// Energy: deposited within 0.5 % of ∫P dt when the path is inside the map (issue acceptance);
// the Gaussian sums to its integral far better than that, so assert 1e-6 and report.
TEST(BatchChain, EnergyBalance)
{
  for (const char* job : {"corner", "corner:speed=1,angle=90"})
  {
    const ChainRun run = runJob(job, {});
    const RunMetrics& m = run.metrics;
    EXPECT_EQ(m.dropped_samples, 0u);
    EXPECT_GT(m.commanded_energy_j, 0.0);
    EXPECT_EQ(m.energy_outside_map_j, 0.0);
    EXPECT_NEAR(m.deposited_energy_j, m.commanded_energy_j, 0.005 * m.commanded_energy_j);
    EXPECT_NEAR(m.deposited_energy_j, m.commanded_energy_j, 1e-6 * m.commanded_energy_j);
    // Laser on for the marked length / speed, to within one sample per edge.
    const double expected_on = (job == std::string("corner") ? 0.008 / 2.0 : 0.008 / 1.0);
    EXPECT_NEAR(m.laser_on_time_s, expected_on, 2e-5) << job;
    std::printf("%s: commanded %.9f J, deposited %.9f J (%+.2e)\n", job, m.commanded_energy_j, m.deposited_energy_j,
                m.deposited_energy_j / m.commanded_energy_j - 1);
  }
}
