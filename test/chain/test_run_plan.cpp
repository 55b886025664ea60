// The run plan against the runs it plans (samples, machine time, tiles, memory), the limits at
// their edges, the physical bounds at just inside / just outside, warnings, and out-of-memory.
#include <gtest/gtest.h>
#include <sys/resource.h>

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>

#include "fixtures/chain_fixture.hpp"
#include "scanhead/chain/run_plan.hpp"
#include "scanhead/common/errors.hpp"
#include "scanhead/job/job_stats.hpp"
#include "scanhead/metrics/metrics_report.hpp"

using namespace scanhead;
using scanhead::test_support::kConfig;

namespace
{
struct Planned
{
  ChainConfig config;
  Job job;
  RunPlan plan;
};

Planned planOf(const std::string& spec, const std::vector<std::string>& overrides, const OpticalModel& optics)
{
  Planned p{loadChainConfig(kConfig, overrides), Job(), RunPlan()};
  p.job = loadJob(spec, p.config.cam);
  validateScanJob(p.job, p.config.optics.field_half_width_m);
  p.plan = planRun(p.config, p.job, optics);
  return p;
}

const OpticalModel& optics()
{
  static const OpticalModel model = loadOpticalModel(loadChainConfig(kConfig, {}).optics);
  return model;
}

std::string errorOf(const std::function<void()>& f)
{
  try
  {
    f();
  }
  catch (const std::exception& e)
  {
    return e.what();
  }
  return "";
}

Job oneMark(double speed_mps, double power_w)
{
  Job job;
  job.name = "one_mark";
  job.source = "test";
  Polyline line;
  line.type = PolylineType::Mark;
  line.speed_mps = speed_mps;
  line.power_w = power_w;
  line.points = {Eigen::Vector2d(0.0, 0.0), Eigen::Vector2d(0.002, 0.0)};
  job.polylines.push_back(line);
  return job;
}
}  // namespace

// The plan's sample count and machine time are the NC's, exactly (the same formulas), on fixed and
// adaptive filters, skywriting, delays and a THESIS recipe; the program time is the job statistics'
// ideal time when the NC adds nothing. The touched tiles bound the map's from above within 2×; the
// energy stage's memory (map, path, index, grids, track) is within a factor 2 of the plan's parts.
TEST(RunPlan, MatchesTheRun)
{
  struct Case
  {
    const char* spec;
    std::vector<std::string> overrides;
  };
  const std::vector<Case> cases = {
      {"corner", {}},
      {"hatch", {}},
      {"hatch", {"nc.filter_mode=adaptive"}},
      {"corner", {"nc.skywriting.enabled=true", "nc.mark_delay_s=1e-4", "nc.polygon_delay_s=5e-5"}},
      {"hatch", {"nc.cap_speeds=true", "recipe.preset=thesis3"}},
      {"hatch:size=0.002", {"energy.method=sampled", "stream.threads=1", "nc.period_s=2e-5"}},
  };
  for (const Case& c : cases)
  {
    const Planned p = planOf(c.spec, c.overrides, optics());
    BatchChain chain(p.config, optics());
    const RunMetrics m = chain.run(p.job);
    const std::string what = std::string(c.spec) + (c.overrides.empty() ? "" : " " + c.overrides[0]);
    EXPECT_EQ(p.plan.samples, static_cast<double>(chain.totalSamples())) << what;
    EXPECT_EQ(p.plan.samples, static_cast<double>(m.samples)) << what;
    EXPECT_NEAR(p.plan.machine_time_s, m.duration_s, 1e-12 * m.duration_s) << what;
    EXPECT_EQ(p.plan.program_duration_s, chain.nc().pathDuration()) << what;
    EXPECT_EQ(p.plan.filter_delay_s, chain.nc().plan().filter_delay_s) << what;
    EXPECT_EQ(chain.plan().samples, p.plan.samples) << what;  // what run() planned
    // Laser-on samples: the gate's windows, each rounded up to whole samples.
    EXPECT_NEAR(p.plan.laser_on_samples * p.config.nc.period_s, m.laser_on_time_s,
                p.config.nc.period_s * (1.0 + static_cast<double>(chain.nc().program().gate.windows().size())))
        << what;
    EXPECT_GE(p.plan.map_tiles_touched, static_cast<double>(m.map_tiles)) << what;
    EXPECT_LE(p.plan.map_tiles_touched, 2.0 * static_cast<double>(m.map_tiles)) << what;
    const MemoryEstimate& e = p.plan.memory;
    const double stage =
        e.map_directory + e.map_tiles + e.contour_path + e.contour_index + e.fill_grid + e.track + e.program / 5.0;
    EXPECT_GT(stage, 0.5 * static_cast<double>(m.peak_memory_bytes)) << what;
    EXPECT_LT(stage, 2.0 * static_cast<double>(m.peak_memory_bytes)) << what;
    std::printf("%-40s samples %.0f (run %llu), tiles %.0f (run %llu), stage memory %.3g MB (run %.3g MB)\n",
                what.c_str(), p.plan.samples, static_cast<unsigned long long>(m.samples), p.plan.map_tiles_touched,
                static_cast<unsigned long long>(m.map_tiles), stage / 1e6, m.peak_memory_bytes / 1e6);
  }
  // Program time = Σ L/v of the job statistics when the NC adds no hold.
  const Planned hatch = planOf("hatch", {}, optics());
  EXPECT_NEAR(hatch.plan.program_duration_s, computeJobStats(hatch.job, 4.5).ideal_time_s, 1e-12);
}

// The plan is analytic: a job of 1e9 s (speed 1e-12 m/s) plans in milliseconds and is refused.
TEST(RunPlan, AbsurdJobsPlanAtOnceAndAreRefused)
{
  const ChainConfig config = loadChainConfig(kConfig, {});
  const auto start = std::chrono::steady_clock::now();
  const RunPlan plan = planRun(config, oneMark(1e-12, 200.0), optics());
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 1.0);
  EXPECT_NEAR(plan.program_duration_s, 0.002 / 1e-12, 1e-6 * 2e9);
  const std::string error = errorOf([&] { enforceRunLimits(plan, config.limits, physicalMemoryBytes()); });
  EXPECT_NE(error.find("limits.max_machine_time_s"), std::string::npos) << error;
  // Through BatchChain::run: refused before the stages allocate anything for it.
  BatchChain chain(config, optics());
  EXPECT_THROW(chain.run(oneMark(1e-12, 200.0)), ConfigError);
  EXPECT_GT(chain.plan().machine_time_s, 1e9);
}

// Each limit at its edge: a plan exactly at the bound runs, one just beyond is refused with the key.
TEST(RunPlan, LimitsAtTheirEdges)
{
  const Planned p = planOf("hatch", {}, optics());
  LimitsConfig limits;
  limits.max_machine_time_s = p.plan.machine_time_s;
  limits.max_samples = p.plan.samples;
  limits.max_memory_bytes = p.plan.memory.total();
  limits.max_memory_fraction = 1.0;
  const std::uint64_t physical = 1ull << 40;
  EXPECT_EQ(errorOf([&] { enforceRunLimits(p.plan, limits, physical); }), "");
  LimitsConfig l = limits;
  l.max_machine_time_s = std::nextafter(p.plan.machine_time_s, 0.0);
  EXPECT_NE(errorOf([&] { enforceRunLimits(p.plan, l, physical); }).find("limits.max_machine_time_s"),
            std::string::npos);
  l = limits;
  l.max_samples = p.plan.samples - 1.0;
  EXPECT_NE(errorOf([&] { enforceRunLimits(p.plan, l, physical); }).find("limits.max_samples"), std::string::npos);
  l = limits;
  l.max_memory_bytes = std::nextafter(p.plan.memory.total(), 0.0);
  const std::string memory = errorOf([&] { enforceRunLimits(p.plan, l, physical); });
  EXPECT_NE(memory.find("limits.max_memory_bytes"), std::string::npos) << memory;
  EXPECT_NE(memory.find("the largest part"), std::string::npos) << memory;
  l = limits;
  l.max_memory_bytes = 0.0;
  l.max_memory_fraction = 0.999 * p.plan.memory.total() / static_cast<double>(physical);
  EXPECT_NE(errorOf([&] { enforceRunLimits(p.plan, l, physical); }).find("limits.max_memory_fraction"),
            std::string::npos);
  // The physical memory is the machine's (sysconf; /proc/meminfo agrees within a few %).
  EXPECT_GT(physicalMemoryBytes(), 100ull << 20);
  // A big map directory and chunk size show in the estimate and name their key.
  const Planned big = planOf("hatch", {"stream.chunk_samples=1000000"}, optics());
  EXPECT_NE(big.plan.memory.largestPart().find("stream.chunk_samples"), std::string::npos);
}

// The galvos' reach: the no-load speed U/Ke times the spot speed per joint rate. Just inside runs
// the plan, just outside is an error naming the field; 1e300 m/s too.
TEST(RunPlan, SpeedBoundAtItsEdge)
{
  const ChainConfig config = loadChainConfig(kConfig, {});
  const SpeedBounds b = galvoSpeedBounds(config, optics());
  EXPECT_DOUBLE_EQ(b.no_load_speed_radps.x(), 30.0 / 0.024);  // 1250 rad/s
  // ≈ 2·d·ω0 per axis at the centre (d ≈ 0.7 m), summed over both axes, larger towards the corners.
  EXPECT_GT(b.max_spot_speed_mps, 2.0 * 2.0 * 0.6 * 1250.0);
  EXPECT_LT(b.max_spot_speed_mps, 2.0 * 2.0 * 0.9 * 1250.0 * 1.3);
  EXPECT_NEAR(b.saturation_speed_mps, 25.0 / 0.716, 0.5);  // nc_config.hpp's g = 0.716 rad/m
  const double inside = b.max_spot_speed_mps * (1.0 - 1e-12), outside = b.max_spot_speed_mps * (1.0 + 1e-12);
  EXPECT_EQ(errorOf([&] { planRun(config, oneMark(inside, 200.0), optics()); }), "");
  const std::string error = errorOf([&] { planRun(config, oneMark(outside, 200.0), optics()); });
  EXPECT_NE(error.find("polylines[0].speed"), std::string::npos) << error;
  EXPECT_NE(error.find("above what the galvos can reach"), std::string::npos) << error;
  EXPECT_THROW(planRun(config, oneMark(1e300, 200.0), optics()), InputError);
  // The recipe's speeds when it overrides the job: a ConfigError naming the key.
  const ChainConfig custom =
      loadChainConfig(kConfig, {"recipe.preset=custom", "recipe.jump_speed_mps=" + std::to_string(2.0 * outside)});
  EXPECT_NE(errorOf([&] { planRun(custom, oneMark(1.0, 200.0), optics()); }).find("recipe.jump_speed_mps"),
            std::string::npos);
  const ChainConfig implicit = loadChainConfig(kConfig, {"nc.implicit_jump_speed_mps=1e4"});
  EXPECT_NE(errorOf([&] { planRun(implicit, oneMark(1.0, 200.0), optics()); }).find("nc.implicit_jump_speed_mps"),
            std::string::npos);
}

// Powers: 1 MW is the bound (error beyond), 1 kW the warning threshold; mark speeds above 10 m/s and
// speeds above the NC's saturation warn; each warning once.
TEST(RunPlan, PowerBoundsAndWarnings)
{
  const ChainConfig config = loadChainConfig(kConfig, {});
  EXPECT_EQ(errorOf([&] { planRun(config, oneMark(1.0, kMaxLaserPower_w), optics()); }), "");
  EXPECT_NE(errorOf([&] {
              planRun(config, oneMark(1.0, std::nextafter(kMaxLaserPower_w, 2e6)), optics());
            }).find("polylines[0].power"),
            std::string::npos);
  EXPECT_NE(errorOf([] { loadChainConfig(kConfig, {"recipe.hatch_power_w=1.000001e6"}); }).find("recipe.hatch_power_w"),
            std::string::npos);
  EXPECT_EQ(errorOf([] { loadChainConfig(kConfig, {"recipe.hatch_power_w=1e6"}); }), "");
  EXPECT_NE(errorOf([] { loadChainConfig(kConfig, {"cam.mark_power_w=2e6"}); }).find("cam.mark_power_w"),
            std::string::npos);
  EXPECT_TRUE(planRun(config, oneMark(1.0, 1000.0), optics()).warnings.empty());
  std::vector<std::string> w = planRun(config, oneMark(1.0, 1000.001), optics()).warnings;
  ASSERT_EQ(w.size(), 1u);
  EXPECT_NE(w[0].find("~1 kW"), std::string::npos) << w[0];
  EXPECT_TRUE(planRun(config, oneMark(10.0, 200.0), optics()).warnings.empty());
  w = planRun(config, oneMark(10.001, 200.0), optics()).warnings;
  ASSERT_EQ(w.size(), 1u);
  EXPECT_NE(w[0].find("LPBF mark speeds"), std::string::npos) << w[0];
  w = planRun(config, oneMark(40.0, 200.0), optics()).warnings;
  ASSERT_EQ(w.size(), 2u);  // above 10 m/s and above the NC's saturation (34.9 m/s)
  EXPECT_NE(w[1].find("nc.max_joint_speed_radps"), std::string::npos) << w[1];
  // Config warnings at their edges: pixel d/5, FIR 2 ms, tail 1 s.
  EXPECT_TRUE(
      planRun(loadChainConfig(kConfig, {"energy.pixel_m=14e-6"}), oneMark(1.0, 200.0), optics()).warnings.empty());
  EXPECT_EQ(
      planRun(loadChainConfig(kConfig, {"energy.pixel_m=14.001e-6"}), oneMark(1.0, 200.0), optics()).warnings.size(),
      1u);
  EXPECT_TRUE(planRun(loadChainConfig(kConfig, {"nc.fir_t1_s=2e-3"}), oneMark(1.0, 200.0), optics()).warnings.empty());
  EXPECT_EQ(planRun(loadChainConfig(kConfig, {"nc.fir_t1_s=2.001e-3"}), oneMark(1.0, 200.0), optics()).warnings.size(),
            1u);
  EXPECT_EQ(planRun(loadChainConfig(kConfig, {"nc.tail_s=1.001"}), oneMark(1.0, 200.0), optics()).warnings.size(), 1u);
}

// A run with warnings: each goes to the sink once and into the metrics; metrics.yaml lists them
// under `warnings:` and has no such key when there is none (the golden files' bytes).
TEST(RunPlan, WarningsReachTheSinkAndTheMetrics)
{
  const ChainConfig config = loadChainConfig(kConfig, {"energy.pixel_m=2e-5"});
  BatchChain chain(config, optics());
  std::vector<std::string> seen;
  chain.setWarningSink([&](const std::string& w) { seen.push_back(w); });
  const RunMetrics m = chain.run(oneMark(1.0, 1500.0));
  ASSERT_EQ(seen.size(), 2u);
  EXPECT_EQ(m.warnings, seen);
  const std::string yaml = metricsToYaml(m);
  EXPECT_NE(yaml.find("warnings:  #"), std::string::npos);
  EXPECT_NE(yaml.find("  - \"test: polylines[0].power = 1500 W"), std::string::npos) << yaml.substr(0, 600);
  BatchChain clean(loadChainConfig(kConfig, {}), optics());
  clean.setWarningSink([&](const std::string& w) { seen.push_back(w); });
  const RunMetrics quiet = clean.run(oneMark(1.0, 200.0));
  EXPECT_EQ(seen.size(), 2u);
  EXPECT_EQ(metricsToYaml(quiet).find("warnings"), std::string::npos);
}

// No std::bad_alloc reaches the caller: with the address space capped, a run whose chunks do not
// fit fails with a ConfigError naming the stage and the settings (in a child process).
TEST(RunPlan, OutOfMemoryBecomesAConfigError)
{
#if defined(__SANITIZE_ADDRESS__)
  GTEST_SKIP() << "an address-space cap makes ASan abort instead of throwing std::bad_alloc";
#endif
  EXPECT_EXIT(
      {
        const ChainConfig config = loadChainConfig(kConfig, {"stream.chunk_samples=1000000", "stream.threads=1",
                                                             "nc.tail_s=10", "limits.max_memory_fraction=1"});
        BatchChain chain(config, optics());
        const Job job = loadJob("hatch", config.cam);
        rlimit cap{};
        getrlimit(RLIMIT_AS, &cap);
        // The current mappings plus 64 MB: a million-sample chunk (~1 GB over the streams) cannot fit.
        std::FILE* f = std::fopen("/proc/self/statm", "r");
        unsigned long pages = 0;
        if (f == nullptr || std::fscanf(f, "%lu", &pages) != 1)
          std::exit(3);
        std::fclose(f);
        cap.rlim_cur = pages * static_cast<unsigned long>(sysconf(_SC_PAGE_SIZE)) + (64ul << 20);
        setrlimit(RLIMIT_AS, &cap);
        try
        {
          chain.run(job);
        }
        catch (const ConfigError& e)
        {
          const std::string text = e.what();
          std::exit(text.find("out of memory in the chain") != std::string::npos &&
                            text.find("stream.chunk_samples") != std::string::npos
                        ? 0
                        : 2);
        }
        catch (...)
        {
          std::exit(4);
        }
        std::exit(5);
      },
      ::testing::ExitedWithCode(0), "");
}

// The text for the user: two lines, the machine time and the key figures.
TEST(RunPlan, Text)
{
  const Planned p = planOf("hatch", {}, optics());
  const std::string text = runPlanText(p.plan);
  EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 2);
  EXPECT_NE(text.find("260 ms of machine time"), std::string::npos) << text;
  EXPECT_NE(text.find("25951 samples"), std::string::npos) << text;
  EXPECT_NE(text.find("an estimate"), std::string::npos) << text;
}
