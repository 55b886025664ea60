// scanhead_benchmark: throughput of each stage and real-time factor of the in-process chain.
// Not a test: run it on a quiet machine. Times are wall-clock (steady_clock) per stage call.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <iostream>
#include <string>
#include <vector>

#include "benchmark_contour_error.hpp"
#include "benchmark_stroke_deposit.hpp"
#include "process_memory.hpp"
#include "scanhead/chain/batch_chain.hpp"
#include "scanhead/chain/config_io.hpp"
#include "scanhead/chain/energy_sink_stage.hpp"
#include "scanhead/job/formats/job_io.hpp"
#include "scanhead/job/generators/scan_generators.hpp"
#include "scanhead/job/generators/shape.hpp"
#include "scanhead/job/job_files.hpp"
#include "scanhead/optics/correction_table.hpp"
#include "scanhead/servo/galvo_servo.hpp"
#include "support/command_line.hpp"
#include "support/tool_errors.hpp"

using namespace scanhead;
using Clock = std::chrono::steady_clock;

namespace
{
double seconds(Clock::duration d)
{
  return std::chrono::duration<double>(d).count();
}

struct Stats
{
  std::vector<double> values;
  double mean() const
  {
    double s = 0;
    for (double v : values)
      s += v;
    return s / values.size();
  }
  double min() const { return *std::min_element(values.begin(), values.end()); }
  double max() const { return *std::max_element(values.begin(), values.end()); }
};

/// One run, timing each stage's calls separately; returns seconds per stage + setup + total.
std::vector<double> timedRun(const ChainConfig& config, const OpticalModel& optics, const Job& job,
                             std::uint64_t& samples)
{
  const auto t_setup = Clock::now();
  // The stages as the batch chain and the nodes drive them (chain_stages.hpp).
  NcStage nc(config, optics);
  ServoStage servo(config.servo);
  OpticsStage stage(optics);
  EnergySinkStage energy(config);
  nc.reset(job);
  const PlannedJob planned{job, nc.plan()};
  servo.reset({nc.plan().period_s});
  stage.reset({});
  energy.reset(planned);
  std::vector<double> t(6, 0.0);  // nc, servo, optics, energy, setup, total
  t[4] = seconds(Clock::now() - t_setup);
  while (!nc.done())
  {
    auto a = Clock::now();
    const NcOutput out = nc.process(config.stream.chunk_samples);
    auto b = Clock::now();
    const JointChunk joints = servo.process(out.setpoint);
    auto c = Clock::now();
    const SpotChunk spots = stage.process({out.setpoint, joints, out.laser});
    auto d = Clock::now();
    energy.process(spots);
    auto e = Clock::now();
    t[0] += seconds(b - a);
    t[1] += seconds(c - b);
    t[2] += seconds(d - c);
    t[3] += seconds(e - d);
  }
  auto f = Clock::now();
  energy.finish();
  t[3] += seconds(Clock::now() - f);
  t[5] = t[0] + t[1] + t[2] + t[3] + t[4];
  samples = nc.plan().total_samples;
  return t;
}

void benchmark(const ChainConfig& config, const OpticalModel& optics, const std::string& spec, int repeat)
{
  const Job job = loadJob(spec, config.cam);
  validateScanJob(job, config.optics.field_half_width_m);
  std::vector<Stats> stats(6);
  std::uint64_t samples = 0;
  timedRun(config, optics, job, samples);  // warm-up: page faults, caches
  for (int r = 0; r < repeat; ++r)
  {
    const auto t = timedRun(config, optics, job, samples);
    for (std::size_t i = 0; i < t.size(); ++i)
      stats[i].values.push_back(t[i]);
  }
  const double job_time = samples * config.nc.period_s;
  std::printf("\njob %s: %llu samples = %.2f ms of machine time, %d runs, chunk %zu samples\n", spec.c_str(),
              static_cast<unsigned long long>(samples), job_time * 1e3, repeat, config.stream.chunk_samples);
  std::printf("%-22s %14s %14s %14s %12s\n", "stage", "Msamples/s", "worst Ms/s", "best Ms/s", "share");
  const char* names[] = {"nc_interpolator", "galvo_servo", "optical_chain", "energy (map+metrics)",
                         "setup (plan, alloc)"};
  for (int i = 0; i < 5; ++i)
    std::printf("%-22s %14.2f %14.2f %14.2f %11.1f%%\n", names[i], samples / stats[i].mean() * 1e-6,
                samples / stats[i].max() * 1e-6, samples / stats[i].min() * 1e-6,
                100 * stats[i].mean() / stats[5].mean());
  std::printf("%-22s %14.2f   real-time factor: mean %.1fx, worst %.1fx, best %.1fx\n", "stages one by one",
              samples / stats[5].mean() * 1e-6, job_time / stats[5].mean(), job_time / stats[5].max(),
              job_time / stats[5].min());
  // The chain as scanhead_run drives it: BatchChain, pipelined on stream.threads threads.
  Stats pipeline;
  for (int r = 0; r < repeat; ++r)
  {
    const auto start = Clock::now();
    BatchChain chain(config, optics);
    chain.run(job);
    pipeline.values.push_back(seconds(Clock::now() - start));
  }
  char label[64];
  std::snprintf(label, sizeof label, "batch chain, %zu thread%s", config.stream.threads,
                config.stream.threads > 1 ? "s" : "");
  std::printf("%-22s %14.2f   real-time factor: mean %.1fx, worst %.1fx, best %.1fx\n", label,
              samples / pipeline.mean() * 1e-6, job_time / pipeline.mean(), job_time / pipeline.max(),
              job_time / pipeline.min());
  std::printf("process peak memory so far (VmHWM): %.1f MiB\n", processPeakResidentBytes() / 1048576.0);
}
/// Wall time per stage against job length: square hatches at 1 m/s from a few ms to ~300 s of
/// machine time (100 µm spacing up to 30 mm squares, then denser lines on 30 mm so that the map
/// stays in the tile cache), one run each after a warm-up; one CSV row per job.
void benchmarkScaling(const ChainConfig& config, const OpticalModel& optics, const std::string& csv_path)
{
  const std::pair<double, double> hatches[] = {{0.0002, 1e-4}, {0.0005, 1e-4}, {0.001, 1e-4}, {0.002, 1e-4},
                                               {0.005, 1e-4},  {0.01, 1e-4},   {0.03, 1e-4},  {0.03, 3e-5},
                                               {0.03, 1e-5},   {0.03, 3e-6}};
  std::ofstream csv(csv_path);
  if (!csv)
    throw std::runtime_error(csv_path + ": cannot write");
  csv << "job,samples,machine_s,nc_s,servo_s,optics_s,energy_s,setup_s,stages_s,batch_chain_s\n";
  std::printf("\nscaling: wall time per stage against job length -> %s\n%-40s %12s %10s %10s %10s\n", csv_path.c_str(),
              "job", "machine s", "stages s", "chain s", "x real");
  bool warm = false;
  for (const auto& [size_m, spacing_m] : hatches)
  {
    char spec[96];
    std::snprintf(spec, sizeof spec, "hatch:size=%g,spacing=%g,speed=1", size_m, spacing_m);
    const Job job = loadJob(spec, config.cam);
    validateScanJob(job, config.optics.field_half_width_m);
    std::uint64_t samples = 0;
    if (!warm)
      timedRun(config, optics, job, samples);  // page faults, caches
    warm = true;
    const std::vector<double> t = timedRun(config, optics, job, samples);
    const auto start = Clock::now();
    BatchChain chain(config, optics);
    chain.run(job);
    const double chain_s = seconds(Clock::now() - start);
    const double machine_s = static_cast<double>(samples) * config.nc.period_s;
    csv << '"' << spec << "\"," << samples << ',' << machine_s;  // the spec has commas: quoted
    for (const double v : t)
      csv << ',' << v;
    csv << ',' << chain_s << '\n';
    std::printf("%-40s %12.4g %10.4g %10.4g %10.1f\n", spec, machine_s, t[5], chain_s, machine_s / chain_s);
    std::fflush(stdout);
  }
}

/// NC throughput for each option of issue 3, alone (no downstream stage), on one job.
void benchmarkNcOptions(const std::string& config_path, const std::vector<std::string>& overrides,
                        const OpticalModel& optics, const std::string& spec, int repeat)
{
  struct Option
  {
    const char* name;
    std::vector<std::string> settings;
  };
  const std::vector<Option> options = {
      {"default (fixed FIRs, Newton IGT)", {}},
      {"igt table bilinear 65x65", {"nc.igt.mode=table"}},
      {"igt table bicubic 65x65", {"nc.igt.mode=table", "nc.igt.table_interpolation=bicubic"}},
      {"adaptive filters", {"nc.filter_mode=adaptive"}},
      {"delays (mark/jump/polygon)", {"nc.mark_delay_s=100e-6", "nc.jump_delay_s=300e-6", "nc.polygon_delay_s=50e-6"}},
      {"skywriting", {"nc.skywriting.enabled=true"}},
      {"power ~ speed", {"nc.power_mode=speed"}},
      {"quantisation 16 bit", {"nc.quantisation_bits=16"}},
      {"debug signals", {"nc.debug=true"}},
  };
  std::printf("\nNC alone on %s, %d runs each\n%-36s %12s %12s %10s\n", spec.c_str(), repeat, "option", "samples",
              "Msamples/s", "vs default");
  double reference = 0.0;
  for (const Option& option : options)
  {
    std::vector<std::string> settings = overrides;
    settings.insert(settings.end(), option.settings.begin(), option.settings.end());
    const ChainConfig config = loadChainConfig(resolvePackagePath(config_path), settings);
    const Job job = loadJob(spec, config.cam);
    validateScanJob(job, config.optics.field_half_width_m);
    NcInterpolator nc(config.nc, resolveRecipe(config.recipe), optics, &config.servo);
    Stats stats;
    std::uint64_t samples = 0;
    for (int r = 0; r <= repeat; ++r)  // run 0 warms up
    {
      const auto start = Clock::now();
      nc.start(job);
      while (!nc.done())
        nc.process(config.stream.chunk_samples);
      if (r > 0)
        stats.values.push_back(seconds(Clock::now() - start));
      samples = nc.totalSamples();
    }
    const double rate = samples / stats.mean();
    if (reference == 0.0)
      reference = rate;
    std::printf("%-36s %12llu %12.2f %9.2fx\n", option.name, static_cast<unsigned long long>(samples), rate * 1e-6,
                rate / reference);
  }
}
/// Spots per second of the optical models: direct (ray trace, on the config's machine), Newton
/// inverse (warm-started along a raster, as the NC uses it) and the correction-table inverse.
void benchmarkOpticalModels(const ChainConfig& config, const OpticalModel& optics, int repeat)
{
  const int side = 200;  // a raster of side² points over the field
  const double h = 0.95 * config.optics.field_half_width_m;
  std::vector<Eigen::Vector2d> spots, angles;
  for (int j = 0; j < side; ++j)
    for (int i = 0; i < side; ++i)
    {
      const int k = (j % 2 == 0) ? i : side - 1 - i;  // serpentine: neighbours stay close
      spots.emplace_back(-h + 2 * h * k / (side - 1), -h + 2 * h * j / (side - 1));
    }
  Eigen::Vector2d q = Eigen::Vector2d::Zero();
  for (const auto& x : spots)
    angles.push_back(q = optics.inverse(x, q));
  const CorrectionTable table = CorrectionTable::build(optics, 65, config.optics.field_half_width_m);
  auto rate = [&](const std::function<double()>& pass) {
    Stats stats;
    double sink = 0.0;
    for (int r = 0; r <= repeat; ++r)
    {
      const auto start = Clock::now();
      sink += pass();
      if (r > 0)
        stats.values.push_back(seconds(Clock::now() - start));
    }
    return spots.size() / stats.mean() + 0.0 * sink;
  };
  const double direct = rate([&] {
    double s = 0.0;
    for (const auto& a : angles)
      s += optics.spot(a).x();
    return s;
  });
  const double newton = rate([&] {
    double s = 0.0;
    Eigen::Vector2d guess = angles.front();
    for (const auto& x : spots)
      s += (guess = optics.inverse(x, guess)).x();
    return s;
  });
  const double bilinear = rate([&] {
    double s = 0.0;
    for (const auto& x : spots)
      s += table.joints(x, TableInterpolation::Bilinear).x();
    return s;
  });
  const double bicubic = rate([&] {
    double s = 0.0;
    for (const auto& x : spots)
      s += table.joints(x, TableInterpolation::Bicubic).x();
    return s;
  });
  std::printf("\noptical models (machine: optics.defects = %s), %zu points over the field, %d runs\n",
              config.optics.defects.c_str(), spots.size(), repeat);
  std::printf("%-44s %10.2f M spots/s\n", "direct model (ray trace)", direct * 1e-6);
  std::printf("%-44s %10.2f M spots/s\n", "inverse, Newton (warm-started along a raster)", newton * 1e-6);
  std::printf("%-44s %10.2f M spots/s\n", "inverse, table 65x65 bilinear", bilinear * 1e-6);
  std::printf("%-44s %10.2f M spots/s\n", "inverse, table 65x65 bicubic", bicubic * 1e-6);
}
}  // namespace

/// The servo model alone (GalvoServo::process on 1000-sample chunks, 400 in a row), ns per sample and
/// axis, best of \p repeat; and the hatch generator (100 mm square at 100 µm: 1000 lines). These were
/// timed assertions of the test suite (GalvoServo.Throughput < 200 / 400 ns, ScanGenerators.FastEnough
/// < 50 ms), which failed under sanitizers and on loaded machines: a figure, not a test.
void benchmarkServoAndGenerator(int repeat)
{
  constexpr double kTs = 1e-5;
  auto servo_ns = [&](const std::string& model) {
    ServoConfig cfg;
    cfg.model = model;
    double best = 1e300, sink = 0.0;
    SetpointChunk in;
    in.period_s = kTs;
    in.samples.resize(1000);
    for (std::size_t k = 0; k < in.samples.size(); ++k)
      in.samples[k].position = Eigen::Vector2d(std::sin(k * 1e-3), std::cos(k * 7e-4));
    for (int r = 0; r < repeat; ++r)
    {
      GalvoServo servo(cfg, kTs);
      servo.reset(in.samples[0].position);
      const auto t0 = Clock::now();
      for (int c = 0; c < 400; ++c)
        sink += servo.process(in).samples.back().position[0];
      best = std::min(best, seconds(Clock::now() - t0) * 1e9 / (2.0 * 400 * in.samples.size()));
    }
    if (!std::isfinite(sink))
      throw NumericalError("servo benchmark: non-finite output");
    return best;
  };
  const double simple = servo_ns("closed_loop_3rd_order");
  const double cascade = servo_ns("cascade");
  HatchStyle style;
  style.spacing_m = 100e-6;
  style.meander = true;
  double hatch_s = 1e300;
  std::size_t polylines = 0;
  for (int r = 0; r < repeat; ++r)
  {
    const auto t0 = Clock::now();
    polylines = hatch(makeRectangle(0.1, 0.1), style).polylines.size();
    hatch_s = std::min(hatch_s, seconds(Clock::now() - t0));
  }
  std::printf("\nservo model alone (process(), 1000-sample chunks, best of %d)\n", repeat);
  std::printf("%-44s %10.1f ns per sample per axis\n", "closed_loop_3rd_order", simple);
  std::printf("%-44s %10.1f ns per sample per axis (%.2f M two-axis samples/s)\n", "cascade", cascade,
              1e3 / (2.0 * cascade));
  std::printf("%-44s %10.2f ms (%zu polylines, %.2f us per line)\n", "hatch generator, 100 mm at 100 um", hatch_s * 1e3,
              polylines, hatch_s * 1e6 / 1000.0);
}

int main(int argc, char** argv)
{
  try
  {
    std::vector<std::string> jobs;
    ConfigArguments config_arguments;
    int repeat = 20;
    bool chain_only = false;
    double contour_points_option = 1e7;
    std::string scaling_csv;
    CLI::App app("Throughput of each stage and real-time factor of the in-process chain.", "scanhead_benchmark");
    configureApp(app);
    app.footer(
        "Runs the job N times through NC, servo, optics and energy stage by stage and prints samples per\n"
        "second per stage and the real-time factor (job time / wall time). Default jobs: corner (the NC\n"
        "paper's case) and hatch (5 mm square, 100 um spacing). Then the NC alone on the last job with each\n"
        "NC option (table IGT, adaptive filters, delays, skywriting, power ~ speed, quantisation, debug\n"
        "signals): samples per second and ratio to the default; and the optical models: spots per second\n"
        "of the ray trace, the Newton inverse and the table inverse; the energy deposit of one stroke by\n"
        "length and angle; and the contour-error definitions on a synthetic hatch of --contour-points points.");
    app.add_option("--job", jobs, "a job spec, as scanhead_run --job (repeatable; default: corner and hatch)")
        ->type_name("SPEC")
        ->allow_extra_args(false);
    app.add_option("--repeat", repeat, "runs per job (default 20)")
        ->type_name("N")
        ->transform(check::integerAtLeast(1));
    config_arguments.addTo(app, "nc.fir_t1_s=300e-6");
    app.add_flag("--chain-only", chain_only,
                 "the jobs' chain figures only (e.g. --job squares:recipe=1 --repeat 1 --chain-only)");
    app.add_option("--contour-points", contour_points_option,
                   "points of the synthetic hatch for the contour errors (default 1e7, at least 1000)")
        ->type_name("N")
        ->transform(check::positiveNumber());
    app.add_option("--scaling", scaling_csv,
                   "instead of the above: wall time per stage against job length (square hatches from ms to "
                   "~300 s of machine time) into this CSV (scripts/plot_scaling.py draws it)")
        ->type_name("CSV");
    if (!parseCommandLine(app, argc, argv))
      return 0;
    const std::string& config_path = config_arguments.path;
    const std::vector<std::string>& overrides = config_arguments.overrides;
    const std::size_t contour_points = static_cast<std::size_t>(std::max(1000.0, contour_points_option));
    if (jobs.empty())
      jobs = {"corner", "hatch"};
    const ChainConfig config = loadChainConfig(resolvePackagePath(config_path), overrides);
    const OpticalModel optics = loadOpticalModel(config.optics);
    if (!scaling_csv.empty())
    {
      benchmarkScaling(config, optics, scaling_csv);
      return 0;
    }
    for (const auto& job : jobs)
      benchmark(config, optics, job, repeat);
    if (chain_only)
      return 0;
    benchmarkNcOptions(config_path, overrides, optics, jobs.back(), repeat);
    benchmarkOpticalModels(config, optics, repeat);
    benchmarkServoAndGenerator(repeat);
    benchmarkStrokeDeposit(config.energy, std::min(repeat, 3));
    std::printf("\ncontour error on a synthetic hatch\n");
    benchmarkContourError(std::cout, contour_points);
    return 0;
  }
  catch (const std::exception& e)
  {
    std::cerr << "scanhead_benchmark: error: " << scanhead::toolErrorText(e) << "\n";
    return 1;
  }
}
