// benchmark_energy_trackers: throughput of each tracker the energy stage runs beside the map
// (stream counter, corners, laser settling, laser placement, plot trace, layer quality and its
// nearest-path pass), of the energy map alone by each deposit method, and of the servo models, on a
// job's real stream.
// Not a test and not run by the suite. Times are the thread's CPU time (CLOCK_THREAD_CPUTIME_ID),
// so other processes on the cores matter less; run it on a quiet machine all the same.
//
//   benchmark_energy_trackers [--repeat N] [--only ROW_PREFIX] [--config FILE] JOB [key=value ...]
//   e.g. benchmark_energy_trackers hatch:size=0.02,spacing=0.0001,speed=1
//        benchmark_energy_trackers squares:rows=1,columns=1 recipe.preset=thesis1
//
// The chain (NC, servo, optics) runs once and its chunks are kept in memory; each tracker is then
// fed the same chunks, alone, --repeat times (fresh tracker each time). Rates are samples per second
// (the nearest-path pass: commanded points per second); mean, worst and best run.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "scanhead/chain/chain_stages.hpp"
#include "scanhead/chain/config_io.hpp"
#include "scanhead/chain/energy_stage.hpp"
#include "scanhead/chain/trace_recorder.hpp"
#include "scanhead/common/package_path.hpp"
#include "scanhead/energy/energy_accumulator.hpp"
#include "scanhead/job/formats/job_io.hpp"
#include "scanhead/job/job_files.hpp"
#include "scanhead/metrics/contour_error.hpp"
#include "scanhead/metrics/laser_placement.hpp"
#include "scanhead/metrics/laser_settling.hpp"
#include "scanhead/metrics/layer_quality.hpp"
#include "scanhead/metrics/run_metrics.hpp"
#include "scanhead/nc/nc_stats.hpp"
#include "scanhead/optics/optics_loading.hpp"

using namespace scanhead;

namespace
{
struct Times
{
  std::vector<double> s;
  double mean() const
  {
    double sum = 0.0;
    for (double v : s)
      sum += v;
    return sum / static_cast<double>(s.size());
  }
  double max() const { return *std::max_element(s.begin(), s.end()); }
  double min() const { return *std::min_element(s.begin(), s.end()); }
};

/// \brief Runs \p body \p repeat times (after one warm-up) and prints count / time in M/s.
std::string g_only;  ///< --only PREFIX: run only the rows whose name starts with it

void report(const char* name, double count, int repeat, const std::function<double()>& body)
{
  if (std::string(name).compare(0, g_only.size(), g_only) != 0)
    return;
  body();
  Times t;
  for (int r = 0; r < repeat; ++r)
    t.s.push_back(body());
  std::printf("%-26s %12.2f %12.2f %12.2f   (%.4f s)\n", name, count / t.mean() * 1e-6, count / t.max() * 1e-6,
              count / t.min() * 1e-6, t.mean());
}

double threadSeconds()
{
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

/// \brief CPU time of this thread in \p f [s]: robust to other processes sharing the cores.
template <class F>
double timed(F&& f)
{
  const double a = threadSeconds();
  f();
  return threadSeconds() - a;
}
}  // namespace

int main(int argc, char** argv)
{
  try
  {
    int repeat = 5;
    std::string config_path = "config/scanhead.yaml";
    std::string spec;
    std::vector<std::string> overrides;
    for (int i = 1; i < argc; ++i)
    {
      const std::string a = argv[i];
      if (a == "--repeat" && i + 1 < argc)
        repeat = std::max(1, std::atoi(argv[++i]));
      else if (a == "--only" && i + 1 < argc)
        g_only = argv[++i];
      else if (a == "--config" && i + 1 < argc)
        config_path = argv[++i];
      else if (spec.empty())
        spec = a;
      else
        overrides.push_back(a);
    }
    if (spec.empty())
      spec = "hatch:size=0.02,spacing=0.0001,speed=1";
    const ChainConfig config = loadChainConfig(resolvePackagePath(config_path), overrides);
    const OpticalModel optics = loadOpticalModel(config.optics);
    const Job job = loadJob(spec, config.cam);
    validateScanJob(job, config.optics.field_half_width_m);

    // The stream, once.
    NcStage nc(config, optics);
    nc.reset(job);
    const NcPlan& plan = nc.plan();
    std::vector<SetpointChunk> setpoints;
    std::vector<SpotChunk> chunks;
    {
      ServoStage servo(config.servo);
      OpticsStage stage(optics);
      servo.reset({plan.period_s});
      stage.reset({});
      while (!nc.done())
      {
        const NcOutput out = nc.process(config.stream.chunk_samples);
        const JointChunk joints = servo.process(out.setpoint);
        chunks.push_back(stage.process({out.setpoint, joints, out.laser}));
        setpoints.push_back(out.setpoint);
      }
    }
    double samples = 0.0;
    for (const SpotChunk& c : chunks)
      samples += static_cast<double>(c.samples.size());
    std::printf("job %s: %.0f samples, chunk %zu, %d runs\n", spec.c_str(), samples, config.stream.chunk_samples,
                repeat);
    std::printf("%-26s %12s %12s %12s\n", "tracker", "mean M/s", "worst M/s", "best M/s");

    // Servo models alone on the stored setpoints.
    for (const char* model : {"cascade", "closed_loop_3rd_order"})
    {
      ServoConfig servo_config = config.servo;
      servo_config.model = model;
      const std::string name = std::string("servo ") + model;
      report(name.c_str(), samples, repeat, [&] {
        GalvoServo servo(servo_config, plan.period_s);
        servo.reset(Eigen::Vector2d(setpoints.front().samples.front().position));
        return timed([&] {
          for (const SetpointChunk& c : setpoints)
            servo.process(c);
        });
      });
    }

    const double actual_delay = plan.actualDelay();
    Eigen::Vector2d lo, hi;
    jobMapBounds(job, config.energy.map_margin_m, lo, hi);
    const double lag = config.energy.contour_lag_s >= 0.0 ? config.energy.contour_lag_s : actual_delay;

    // The energy map alone, each deposit method (one thread; the pixels it adds to the map, a measure of its work).
    for (const char* method : {"trapezoid", "exact", "sampled"})
    {
      EnergyConfig energy = config.energy;
      energy.method = method;
      const std::string name = std::string("EnergyAccumulator ") + method;
      double pixels = 0.0;
      report(name.c_str(), samples, repeat, [&] {
        EnergyAccumulator acc(energy, lo, hi);
        const double t = timed([&] {
          for (const SpotChunk& c : chunks)
            acc.process(c);
          acc.finish();
        });
        pixels = static_cast<double>(acc.pixelsDrawn());
        return t;
      });
      if (std::string(name).compare(0, g_only.size(), g_only) == 0 && pixels > 0.0)
        std::printf("  (%.0f pixels added to the map, %.0f a sample)\n", pixels, pixels / samples);
    }

    report("StreamCounter", samples, repeat, [&] {
      StreamCounter counter;
      return timed([&] {
        for (const SpotChunk& c : chunks)
          counter.process(c);
      });
    });
    report("CornerTracker", samples, repeat, [&] {
      CornerTracker corners(findCorners(plan.program.timeline, config.energy.corner_min_angle_deg * M_PI / 180.0),
                            plan.filter_delay_s, actual_delay);
      return timed([&] {
        for (const SpotChunk& c : chunks)
          corners.process(c);
      });
    });
    report("LaserSettlingCheck", samples, repeat, [&] {
      LaserSettlingCheck settling(plan.program, plan.gate_shift_s, plan.filter_delay_s,
                                  config.energy.laser_path_tolerance_m);
      return timed([&] {
        for (const SpotChunk& c : chunks)
          settling.process(c);
      });
    });
    report("LaserPlacement", samples, repeat, [&] {
      LaserPlacement placement(job, config.energy.laser_path_tolerance_m);
      return timed([&] {
        for (const SpotChunk& c : chunks)
          placement.add(c);
      });
    });
    report("TraceRecorder", samples, repeat, [&] {
      TraceRecorder trace(plan.total_samples, 20000);
      return timed([&] {
        for (const SpotChunk& c : chunks)
          trace.process(c);
      });
    });
    report("LayerQuality::process", samples, repeat, [&] {
      LayerQuality quality(config.energy, plan.program.timeline, job, lag, plan.total_samples, lo, hi);
      return timed([&] {
        for (const SpotChunk& c : chunks)
          quality.process(c);
      });
    });
    double commanded = 0.0;
    report("LayerQuality::finish", samples, repeat, [&] {
      LayerQuality quality(config.energy, plan.program.timeline, job, lag, plan.total_samples, lo, hi);
      for (const SpotChunk& c : chunks)
        quality.process(c);
      double s = 0.0;
      s = timed([&] { commanded = static_cast<double>(quality.finish().commanded_points); });
      return s;
    });
    std::printf("  (finish: %.0f commanded points)\n", commanded);
    // The nearest-path pass alone: the index build, then the queries (same-instant bound).
    {
      PathPoints path(lo);
      for (const SpotChunk& c : chunks)
        for (const SpotSample& sample : c.samples)
          path.add(sample.actual);
      const double n = static_cast<double>(path.size());
      report("NearestPathIndex build", n, repeat, [&] { return timed([&] { NearestPathIndex index(path); }); });
      const NearestPathIndex index(path);
      const std::uint64_t lag_samples = static_cast<std::uint64_t>(std::llround(lag / plan.period_s));
      std::vector<Eigen::Vector2d> commands;
      PathTimeline::Cursor cursor;
      for (std::uint64_t k = 0; k * plan.period_s < plan.program.timeline.duration(); ++k)
        commands.push_back(plan.program.timeline.positionAt(static_cast<double>(k) * plan.period_s, cursor));
      const double m = static_cast<double>(commands.size());
      double sink = 0.0;
      report("(b) same instant", m, repeat, [&] {
        return timed([&] {
          for (std::size_t k = 0; k < commands.size(); ++k)
            if (k + lag_samples < path.size())
              sink += sameInstantDistance(path, k + lag_samples, commands[k]);
        });
      });
      report("(a) nearest, (b) as bound", m, repeat, [&] {
        return timed([&] {
          for (std::size_t k = 0; k < commands.size(); ++k)
          {
            const double bound = k + lag_samples < path.size() ? sameInstantDistance(path, k + lag_samples, commands[k])
                                                               : std::numeric_limits<double>::infinity();
            sink += index.distance(commands[k], bound);
          }
        });
      });
      std::printf("  (%.0f commanded points; checksum %.6g)\n", m, sink);
    }
    report("all trackers (1 thread)", samples, repeat, [&] {
      StreamCounter counter;
      CornerTracker corners(findCorners(plan.program.timeline, config.energy.corner_min_angle_deg * M_PI / 180.0),
                            plan.filter_delay_s, actual_delay);
      LaserSettlingCheck settling(plan.program, plan.gate_shift_s, plan.filter_delay_s,
                                  config.energy.laser_path_tolerance_m);
      LaserPlacement placement(job, config.energy.laser_path_tolerance_m);
      TraceRecorder trace(plan.total_samples, 20000);
      LayerQuality quality(config.energy, plan.program.timeline, job, lag, plan.total_samples, lo, hi);
      return timed([&] {
        for (const SpotChunk& c : chunks)
        {
          counter.process(c);
          corners.process(c);
          settling.process(c);
          placement.add(c);
          trace.process(c);
          quality.process(c);
        }
        quality.finish();
      });
    });
    return 0;
  }
  catch (const std::exception& e)
  {
    std::fprintf(stderr, "benchmark_energy_trackers: error: %s\n", e.what());
    return 1;
  }
}
