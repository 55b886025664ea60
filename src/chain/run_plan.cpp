/// \file run_plan.cpp
/// \brief The run plan: machine time, samples, map, memory and wall time before a run; the limits.
#include "scanhead/chain/run_plan.hpp"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "scanhead/chain/energy_stage.hpp"
#include "scanhead/common/errors.hpp"
#include "scanhead/common/number_text.hpp"
#include "scanhead/energy/map_regions.hpp"
#include "scanhead/energy/node_chain.hpp"
#include "scanhead/energy/tiled_energy_map.hpp"
#include "scanhead/job/path_timeline.hpp"
#include "scanhead/job/recipe.hpp"
#include "scanhead/nc/adaptive_fir.hpp"
#include "scanhead/nc/nc_program.hpp"
#include "scanhead/optics/joint_gain.hpp"
#include "scanhead/report/energy_exports.hpp"

namespace scanhead
{
namespace
{
// Memory (bytes), see the header. The base and the per-sample constants were measured with
// /usr/bin/time on scanhead_run (corner, hatch, THESIS layer; Release build).
constexpr double kBaseBytes = 30.0e6;                // process, optics, libraries
constexpr double kImageBytesPerPixel = 10.0;         // an exported image: float map, float TIFF rows, 16-bit PNG
constexpr double kColourSide = 2000.0;               // the colour PNG: at most 2000 px a side, 4 B a pixel
constexpr double kChunkBytesPerSample = 1000.0;      // every stream's chunks in flight + the NC's work arrays
constexpr double kProgramCopies = 5.0;               // NC plan, corner tracker, laser checks, layer metrics, job
constexpr double kPathBytesPerSample = 8.0 + 0.125;  // float x, y + a break bit (path_points.cpp)
constexpr double kIndexBytesPerSample = 8.0;         // nearest-path index elements, cells and items
constexpr double kTrackBytesPerSample = 88.0;        // sizeof(SpotSample)
constexpr double kThermalBytesPerCell = 48.0;
constexpr double kTileBytes = TiledEnergyMap::kTileSide * TiledEnergyMap::kTileSide * 4.0 + 64.0;
// Wall time (seconds), measured rates of the README's performance table (2-core VM).
constexpr double kProducerSecondsPerSample = 0.55e-6;  // NC 3.1 M/s, servo 16 M/s, optics 6.5 M/s
constexpr double kServoSecondsPerStep = 0.065e-6;      // one cascade controller period, both axes
constexpr double kSecondsPerFirTap = 2.0e-9;           // a box FIR's sum, per tap and sample (all filters)
constexpr double kEnergySecondsPerSample = 1.5e-6;     // the layer metrics and the map's bookkeeping
constexpr double kSecondsPerPixel = 9.0e-9;            // a pixel of the band estimate below (≈ 2 weights computed)
constexpr double kSecondsPerNodeWeight = 0.4e-9;       // trapezoid: a weight of a node's square, weighed and added
constexpr double kSetupSeconds = 0.02;                 // the stages' reset and the metrics' last pass
constexpr double kThermalSamplesPerSecond = 3.0e4;
// The actual path leaves the command by up to tens of µm at corners (the servo's following error).
constexpr double kFollowingMargin_m = 20e-6;
// Beyond this many tile visits the touched tiles are bounded by a formula instead of rasterised.
constexpr double kMaxRasterVisits = 6.0e7;
constexpr double kMaxRasterTiles = 134217728.0;  // 2^27 tiles: a 16 MB bitmap

std::string bytesText(double bytes)
{
  char text[64];
  if (bytes >= 1e9)
    std::snprintf(text, sizeof text, "%.3g GB", bytes / 1e9);
  else
    std::snprintf(text, sizeof text, "%.3g MB", bytes / 1e6);
  return text;
}

std::string timeText(double s)
{
  char text[64];
  if (s >= 3600.0)
    std::snprintf(text, sizeof text, "%.3g h", s / 3600.0);
  else if (s >= 1.0 || s == 0.0)
    std::snprintf(text, sizeof text, "%.3g s", s);
  else
    std::snprintf(text, sizeof text, "%.3g ms", s * 1e3);
  return text;
}

/// ceil(x) where x within 1e-9 (relative) of an integer counts as that integer (as the NC's).
double ceilSnapped(double x)
{
  const double nearest = std::round(x);
  if (std::abs(x - nearest) <= 1e-9 * std::max(1.0, std::abs(x)))
    return std::max(0.0, nearest);
  return std::max(0.0, std::ceil(x));
}

/// Taps of a box FIR of \p duration_s at \p period_s (box_filter.hpp: ceil(T/Ts) + 2 at most).
double firTaps(double duration_s, double period_s)
{
  return std::ceil(duration_s / period_s) + 2.0;
}

std::string polylineField(const Job& job, std::size_t p)
{
  return job.source + ": polylines[" + std::to_string(p) + "]";
}

/// Largest footprint radius on the plane [m]: truncation × w, stretched by oblique incidence
/// (1/cos of the largest incidence, ≤ 1.1 over this head's field) and by defocus (Gaussian beam:
/// w(z) = w0·sqrt(1 + (z/zR)²); the field mode adds L·(1/cos θ − 1) ≤ 0.06·L at the field's corner).
double footprintRadius(const EnergyConfig& e)
{
  double z = 0.0;
  if (e.defocus_mode == "fixed")
    z = std::fabs(e.defocus_m);
  else if (e.defocus_mode == "field")
    z = std::fabs(e.defocus_m) + 0.06 * e.focus_distance_m;
  const double zr = e.rayleighLength();
  const double stretch = (e.oblique_incidence ? 1.1 : 1.0) * std::sqrt(1.0 + (z / zr) * (z / zr));
  return e.truncation_radii * 0.5 * e.spot_diameter_m * stretch;
}

/// Tiles the laser-on segments touch: each segment grown by \p radius_m, rasterised at tile
/// resolution (a bitmap over the directory), or bounded by the band areas when that would be costly.
double touchedTiles(const PathTimeline& timeline, double radius_m, const Eigen::Vector2d& origin, double tile_m,
                    std::int64_t tiles_x, std::int64_t tiles_y)
{
  const double all = static_cast<double>(tiles_x) * static_cast<double>(tiles_y);
  const double reach = std::ceil(radius_m / tile_m) * 2.0 + 2.0;  // tiles across a band
  double visits = 0.0, band_tiles = 0.0;
  for (const PathSegment& s : timeline.segments())
  {
    if (!s.mark)
      continue;
    const double steps = std::ceil(s.length_m / (0.5 * tile_m)) + 1.0;
    visits += steps * reach * reach;
    band_tiles += (s.length_m / tile_m + 1.0) * reach;
  }
  if (visits > kMaxRasterVisits || all > kMaxRasterTiles)
    return std::min(all, band_tiles);
  std::vector<bool> touched(static_cast<std::size_t>(all), false);
  double count = 0.0;
  auto mark = [&](const Eigen::Vector2d& p) {
    const auto i0 = static_cast<std::int64_t>(std::floor((p.x() - radius_m - origin.x()) / tile_m));
    const auto i1 = static_cast<std::int64_t>(std::floor((p.x() + radius_m - origin.x()) / tile_m));
    const auto j0 = static_cast<std::int64_t>(std::floor((p.y() - radius_m - origin.y()) / tile_m));
    const auto j1 = static_cast<std::int64_t>(std::floor((p.y() + radius_m - origin.y()) / tile_m));
    for (std::int64_t j = std::max<std::int64_t>(j0, 0); j <= std::min(j1, tiles_y - 1); ++j)
      for (std::int64_t i = std::max<std::int64_t>(i0, 0); i <= std::min(i1, tiles_x - 1); ++i)
      {
        const auto k = static_cast<std::size_t>(j * tiles_x + i);
        if (!touched[k])
        {
          touched[k] = true;
          count += 1.0;
        }
      }
  };
  for (const PathSegment& s : timeline.segments())
  {
    if (!s.mark)
      continue;
    const double steps = std::ceil(s.length_m / (0.5 * tile_m));
    for (double k = 0.0; k <= steps; k += 1.0)
      mark(s.start_m + (steps > 0.0 ? k / steps : 0.0) * (s.end_m - s.start_m));
  }
  return count;
}

/// Which setting a speed or power came from: a key, or a job polyline's field (named on use only:
/// a job may have millions of polylines).
struct SettingSource
{
  const char* key = nullptr;  ///< the config key, or the field of polyline `polyline`
  double value = 0.0;
  std::size_t polyline = 0;
  bool from_job = false;
};

std::string nameOf(const SettingSource& s, const Job& job)
{
  return s.from_job ? polylineField(job, s.polyline) + "." + s.key : std::string(s.key);
}

/// The impossible and the questionable speeds and powers: errors thrown, warnings appended.
void checkSpeedsAndPowers(const ChainConfig& config, const Recipe& recipe, const Job& job, const SpeedBounds& bounds,
                          std::vector<std::string>& warnings)
{
  std::vector<SettingSource> mark_speeds, other_speeds, powers;
  if (recipe.override_job)
  {
    mark_speeds.push_back({"recipe.contour_speed_mps", recipe.contour_speed_mps});
    mark_speeds.push_back({"recipe.hatch_speed_mps", recipe.hatch_speed_mps});
    other_speeds.push_back({"recipe.jump_speed_mps", recipe.jump_speed_mps});
    other_speeds.push_back({"recipe.contour_jump_speed_mps", recipe.contour_jump_speed_mps});
    powers.push_back({"recipe.contour_power_w", recipe.contour_power_w});
    powers.push_back({"recipe.hatch_power_w", recipe.hatch_power_w});
  }
  else
  {
    for (std::size_t p = 0; p < job.polylines.size(); ++p)
    {
      const Polyline& line = job.polylines[p];
      const bool mark = line.type == PolylineType::Mark;
      if (line.dwell_s <= 0.0)
        (mark ? mark_speeds : other_speeds).push_back({"speed", line.speed_mps, p, true});
      if (mark)
        powers.push_back({"power", line.power_w, p, true});
    }
  }
  other_speeds.push_back({"nc.implicit_jump_speed_mps", config.nc.implicit_jump_speed_mps});

  const double v_max = bounds.max_spot_speed_mps;
  auto check_speed = [&](const SettingSource& s) {
    if (!(s.value <= v_max))
    {
      const std::string text =
          nameOf(s, job) + " = " + significantText(s.value, 6) +
          " m/s is above what the galvos can reach: " + significantText(v_max, 4) +
          " m/s (their no-load speed U/Ke = " + significantText(bounds.no_load_speed_radps.minCoeff(), 4) +
          " rad/s, servo.<axis>.plant.supply_voltage_v / torque_constant_nm_per_a, times the "
          "optics' largest spot speed per joint rate over the field)";
      if (!s.from_job)
        throw ConfigError(text);
      throw InputError(text);
    }
  };
  for (const SettingSource& s : mark_speeds)
    check_speed(s);
  for (const SettingSource& s : other_speeds)
    check_speed(s);
  for (const SettingSource& s : powers)
  {
    if (!(s.value <= kMaxLaserPower_w))
      throw InputError(nameOf(s, job) + " = " + significantText(s.value, 6) +
                       " W is above any continuous-wave laser (<= 1e+06 W; LPBF lasers: 200 W - 1 kW)");
  }

  // Questionable: one warning per kind, naming the largest.
  auto warn_above = [&](const std::vector<SettingSource>& list, double bound, const std::string& what) {
    const SettingSource* worst = nullptr;
    std::size_t count = 0;
    for (const SettingSource& s : list)
      if (s.value > bound)
      {
        ++count;
        if (worst == nullptr || s.value > worst->value)
          worst = &s;
      }
    if (worst != nullptr)
      warnings.push_back(nameOf(*worst, job) + " = " + significantText(worst->value, 6) + what +
                         (count > 1 ? " (" + std::to_string(count) + " settings or polylines)" : std::string()));
  };
  warn_above(powers, kLpbfLaserPower_w, " W is above the ~1 kW of LPBF lasers (EOS M 290: 400 W; SLM 280: <= 1 kW)");
  warn_above(mark_speeds, kLpbfMaxMarkSpeed_mps,
             " m/s is above LPBF mark speeds (<= 10 m/s: EOS M 290 up to 7 m/s, SLM 280 up to 10 m/s)");
  std::vector<SettingSource> all_speeds = mark_speeds;
  all_speeds.insert(all_speeds.end(), other_speeds.begin(), other_speeds.end());
  warn_above(all_speeds, bounds.saturation_speed_mps,
             " m/s is above nc.max_joint_speed_radps / g = " + significantText(bounds.saturation_speed_mps, 4) +
                 " m/s: the NC saturates (fixed filters) or caps (adaptive, nc.cap_speeds) the joint speed there");
}

/// Questionable config values (possible, but not what a scan head runs).
void configWarnings(const ChainConfig& config, std::vector<std::string>& warnings)
{
  const EnergyConfig& e = config.energy;
  if (e.pixel_m > kQuestionablePixelPerDiameter * e.spot_diameter_m)
    warnings.push_back("energy.pixel_m = " + significantText(e.pixel_m, 6) +
                       " m is coarser than energy.spot_diameter_m/5 = " +
                       significantText(kQuestionablePixelPerDiameter * e.spot_diameter_m, 6) +
                       " m: fewer than 5 pixels across the spot, the map's peaks and tracks are smeared");
  if (config.nc.filter_mode == "fixed")
  {
    for (const auto& [key, t] :
         {std::make_pair("nc.fir_t1_s", config.nc.fir_t1_s), std::make_pair("nc.fir_t2_s", config.nc.fir_t2_s)})
      if (t > kQuestionableFir_s)
        warnings.push_back(std::string(key) + " = " + significantText(t, 6) +
                           " s is far above the industrial NC's box FIRs (260 and 125 us; THESIS 395 us): every "
                           "corner is rounded by about V*T1/4");
  }
  if (config.nc.tail_s > kQuestionableTail_s)
    warnings.push_back("nc.tail_s = " + significantText(config.nc.tail_s, 6) +
                       " s: the filters and servos settle within milliseconds, the rest is idle samples");
}
}  // namespace

double MemoryEstimate::total() const
{
  return base + chunks + nc_filters + program + map_directory + map_tiles + contour_path + contour_index +
         same_instant + fill_grid + track + thermal + results;
}

std::string MemoryEstimate::largestPart(double* bytes) const
{
  const std::pair<const char*, double> parts[] = {
      {"stream chunks (stream.chunk_samples)", chunks},
      {"NC filters (nc.fir_t1_s, nc.fir_t2_s against nc.period_s)", nc_filters},
      {"NC program (the job's segments)", program},
      {"energy-map directory (energy.pixel_m over the job's extent)", map_directory},
      {"energy-map tiles in memory (energy.tile_cache_bytes)", map_tiles},
      {"actual path for the nearest-path contour error (energy.contour_max_samples)", contour_path},
      {"nearest-path index (energy.contour_max_samples)", contour_index},
      {"same-instant contour ring (energy.same_instant_window_s against nc.period_s)", same_instant},
      {"fill-rate grid (energy.spot_diameter_m over the job's extent)", fill_grid},
      {"track-energy samples (energy.track_max_samples)", track},
      {"thermal grid (thermal.window_m / thermal.cell_m)", thermal},
      {"results images (the overview and energy.crop_parts / energy.crop_regions)", results},
  };
  const auto* best = std::max_element(std::begin(parts), std::end(parts),
                                      [](const auto& a, const auto& b) { return a.second < b.second; });
  if (bytes != nullptr)
    *bytes = best->second;
  return best->first;
}

SpeedBounds galvoSpeedBounds(const ChainConfig& config, const OpticalModel& optics)
{
  SpeedBounds b;
  const GalvoPlantParams& px = config.servo.x.plant;
  const GalvoPlantParams& py = config.servo.y.plant;
  b.no_load_speed_radps = Eigen::Vector2d(px.supply_voltage_v / px.torque_constant_nm_per_a,
                                          py.supply_voltage_v / py.torque_constant_nm_per_a);
  const double h = optics.config().field_half_width_m;
  constexpr int kProbes = 21;
  Eigen::Vector2d q = Eigen::Vector2d::Zero();
  for (int j = 0; j < kProbes; ++j)
    for (int i = 0; i < kProbes; ++i)
    {
      const Eigen::Vector2d x(-h + 2.0 * h * i / (kProbes - 1), -h + 2.0 * h * j / (kProbes - 1));
      q = optics.inverse(x, q);
      const Eigen::Matrix2d jac = optics.jacobian(q);
      b.max_spot_speed_mps = std::max(b.max_spot_speed_mps, jac.col(0).norm() * b.no_load_speed_radps.x() +
                                                                jac.col(1).norm() * b.no_load_speed_radps.y());
    }
  b.joint_rate_gain_rad_per_m = jointRateGains(optics, h).maxCoeff();  // the NC's g, bit for bit
  b.saturation_speed_mps = config.nc.max_joint_speed_radps / b.joint_rate_gain_rad_per_m;
  return b;
}

RunPlan planRun(const ChainConfig& config, const Job& job, const OpticalModel& optics)
{
  RunPlan plan;
  plan.job_name = job.name;
  const NcConfig& nc = config.nc;
  const EnergyConfig& e = config.energy;
  const double ts = nc.period_s;
  plan.period_s = ts;
  plan.tail_s = nc.tail_s;
  plan.speeds = galvoSpeedBounds(config, optics);
  const Recipe recipe = resolveRecipe(config.recipe);
  checkSpeedsAndPowers(config, recipe, job, plan.speeds, plan.warnings);
  configWarnings(config, plan.warnings);

  // The NC program and the sample count, as NcInterpolator::start computes them.
  const double g = plan.speeds.joint_rate_gain_rad_per_m;
  NcProgramOptions options = NcProgramOptions::from(nc, recipe);
  options.speed_cap_mps = nc.speedCap(g);
  const NcProgram program = buildNcProgram(job, options);
  const PathTimeline& timeline = program.timeline;
  plan.segments = timeline.segments().size();
  plan.program_duration_s = timeline.duration();
  double delay = nc.filterDelay(), shift = 0.0;
  if (nc.filter_mode == "adaptive" && timeline.hasPoints())
  {
    const AdaptiveFir fir(timeline, PlaneLimits{nc.max_joint_accel_radps2 / g, nc.max_joint_jerk_radps3 / g});
    delay = fir.delay();
    shift = delay - nc.filterDelay();
  }
  plan.filter_delay_s = delay;
  double end_s = timeline.duration() + 2.0 * delay;
  const auto& windows = program.gate.windows();
  if (!windows.empty())
  {
    plan.last_laser_off_s = windows.back().off_s + shift;
    end_s = std::max(end_s, plan.last_laser_off_s);
  }
  plan.samples = ceilSnapped((end_s + nc.tail_s) / ts) + 1.0;
  plan.machine_time_s = plan.samples * ts;
  for (const LaserWindow& w : windows)
    plan.laser_on_samples += std::max(0.0, std::ceil((w.off_s - w.on_s) / ts));

  // The energy map (as EnergyStage and TiledEnergyMap size it).
  Eigen::Vector2d lo, hi;
  jobMapBounds(job, e.map_margin_m, lo, hi);
  const Eigen::Vector2d extent = hi - lo;
  const double width = std::max(1.0, std::ceil(extent.x() / e.pixel_m));
  const double height = std::max(1.0, std::ceil(extent.y() / e.pixel_m));
  const double side = TiledEnergyMap::kTileSide;
  const double tiles_x = std::ceil(width / side), tiles_y = std::ceil(height / side);
  plan.map_width_px = static_cast<std::int64_t>(std::min(width, 9e18));
  plan.map_height_px = static_cast<std::int64_t>(std::min(height, 9e18));
  plan.map_tiles = tiles_x * tiles_y;
  const double radius = footprintRadius(e);
  const double tile_m = side * e.pixel_m;
  if (plan.map_tiles <= 2147483648.0)  // TiledEnergyMap refuses more (ConfigError)
    plan.map_tiles_touched = touchedTiles(timeline, radius + kFollowingMargin_m, lo, tile_m,
                                          static_cast<std::int64_t>(tiles_x), static_cast<std::int64_t>(tiles_y));
  const double cache_tiles = static_cast<double>(TiledEnergyMap::residentTilesFor(e.tile_cache_bytes));
  plan.map_tiles_resident = std::min(plan.map_tiles_touched, cache_tiles);
  plan.map_spill_bytes = (plan.map_tiles_touched - plan.map_tiles_resident) * side * side * 4.0;

  // The deposit's work: pixel weights (exact: a band of rows along each mark; trapezoid: a footprint square per
  // node, a node per panel of at most w/2; sampled: a footprint square per sub-step).
  const double rows = 2.0 * radius / e.pixel_m;
  for (const PathSegment& s : timeline.segments())
  {
    if (!s.mark || s.power_w <= 0.0)
      continue;
    if (e.method == "trapezoid")
    {
      const double samples = std::max(1.0, s.duration_s / ts);
      const double panel = NodeChain::kMaxPanelRadii * 0.5 * e.spot_diameter_m;
      plan.pixels_drawn += std::max(samples, s.length_m / panel) * rows * rows;
    }
    else if (e.method == "exact")
      plan.pixels_drawn += rows * (s.length_m / e.pixel_m + rows);
    else
    {
      const double samples = std::max(1.0, s.duration_s / ts);
      const double substeps = std::max(1.0, s.length_m / (e.max_substep_radii * 0.5 * e.spot_diameter_m));
      plan.pixels_drawn += std::max(samples, substeps) * rows * rows;
    }
  }

  // Memory.
  MemoryEstimate& m = plan.memory;
  m.base = kBaseBytes;
  m.chunks = static_cast<double>(config.stream.chunk_samples) * kChunkBytesPerSample;
  if (nc.filter_mode == "fixed")
    m.nc_filters = firTaps(nc.fir_t1_s, ts) * 3.0 * (2.0 * 2.0 + 1.0) * 8.0 +
                   firTaps(nc.fir_t2_s, ts) * ((2.0 * 4.0 + 1.0) + (2.0 * 2.0 + 1.0)) * 8.0;
  m.program = static_cast<double>(plan.segments) * sizeof(PathSegment) * kProgramCopies;
  m.map_directory = plan.map_tiles * 4.0;
  const double spilled = plan.map_tiles_touched - plan.map_tiles_resident;
  m.map_tiles = plan.map_tiles_resident * kTileBytes +
                (spilled > 0.0 ? static_cast<double>(TiledEnergyMap::blockCacheBytesFor(e.tile_cache_bytes) +
                                                     TiledEnergyMap::stagingBytesFor(e.tile_cache_bytes))
                               : 0.0) +
                spilled * static_cast<double>(TiledEnergyMap::spilledTileBytes());
  if (plan.samples <= static_cast<double>(e.contour_max_samples))
  {
    m.contour_path = plan.samples * kPathBytesPerSample;
    m.contour_index = plan.samples * kIndexBytesPerSample;
  }
  const double window = std::round(e.same_instant_window_s / ts);
  const double ring = std::exp2(std::ceil(std::log2(2.0 * window + 3.0)));
  const double cache = std::exp2(std::ceil(std::log2(window + 2.0)));
  m.same_instant = ring * 4.0 * 8.0 + cache * 64.0;
  const double fill_w = std::max(1.0, std::ceil(extent.x() / e.spot_diameter_m - 1e-9));
  const double fill_h = std::max(1.0, std::ceil(extent.y() / e.spot_diameter_m - 1e-9));
  m.fill_grid = fill_w * fill_h / 4.0;
  const double kept = std::min(plan.laser_on_samples + static_cast<double>(windows.size()),
                               static_cast<double>(e.track_max_samples) + 1.0);
  m.track = kept > 0.0 ? std::exp2(std::ceil(std::log2(kept))) * kTrackBytesPerSample : 0.0;
  if (config.thermal.enabled)
  {
    const double cells = std::ceil(config.thermal.model.window_m / config.thermal.model.cell_m);
    m.thermal = cells * cells * kThermalBytesPerCell;
  }
  // The results folder's images (energy_exports.cpp): the overview and the crops, each averaged
  // down to at most kOverviewSide / kCropSide pixels a side.
  auto image_bytes = [&](double w, double h, double max_side) {
    const double f = std::max(1.0, std::ceil(std::max(w, h) / max_side));
    const double iw = std::ceil(w / f), ih = std::ceil(h / f);
    return iw * ih * kImageBytesPerPixel + std::min(iw, kColourSide) * std::min(ih, kColourSide) * 4.0;
  };
  m.results = image_bytes(width, height, kOverviewSide);
  std::vector<MapRegion> crops = jobParts(job, 2.0 * e.spot_diameter_m);
  if (crops.size() > e.crop_parts)
    crops.resize(e.crop_parts);
  for (const MapRegion& region : parseMapRegions(e.crop_regions))
    crops.push_back(region);
  for (const MapRegion& crop : crops)
  {
    const Eigen::Vector2d size = (crop.max_corner - crop.min_corner) / e.pixel_m;
    m.results += image_bytes(std::ceil(size.x()) + 1.0, std::ceil(size.y()) + 1.0, kCropSide);
  }

  // Wall time: the producer thread (NC, servo, optics) and the energy stage.
  const bool cascade = config.servo.model == "cascade";
  plan.controller_steps_per_sample = cascade ? std::max(1.0, config.servo.controller_rate_hz * ts) : 1.0;
  double taps = 0.0;
  if (nc.filter_mode == "fixed")
    taps = 3.0 * firTaps(nc.fir_t1_s, ts) + 2.0 * firTaps(nc.fir_t2_s, ts);
  const double producer =
      plan.samples * (kProducerSecondsPerSample + kServoSecondsPerStep * (plan.controller_steps_per_sample - 1.0) +
                      kSecondsPerFirTap * taps);
  const double energy =
      plan.samples * kEnergySecondsPerSample +
      plan.pixels_drawn * (config.energy.method == "trapezoid" ? kSecondsPerNodeWeight : kSecondsPerPixel);
  double thermal = 0.0;
  if (config.thermal.enabled)
  {
    const double window_s =
        config.thermal.duration_s > 0.0
            ? std::min(config.thermal.duration_s, std::max(0.0, plan.machine_time_s - config.thermal.start_s))
            : plan.machine_time_s;
    thermal = window_s / ts / kThermalSamplesPerSecond;
  }
  plan.setup_wall_s = kSetupSeconds;
  plan.wall_time_s =
      kSetupSeconds + (config.stream.threads >= 2 ? std::max(producer, energy) : producer + energy) + thermal;
  return plan;
}

std::uint64_t physicalMemoryBytes()
{
  const long pages = sysconf(_SC_PHYS_PAGES);
  const long page = sysconf(_SC_PAGE_SIZE);
  if (pages <= 0 || page <= 0)
    return 0;
  return static_cast<std::uint64_t>(pages) * static_cast<std::uint64_t>(page);
}

double memoryLimitBytes(const LimitsConfig& limits, std::uint64_t physical_bytes)
{
  double bound = physical_bytes > 0 ? limits.max_memory_fraction * static_cast<double>(physical_bytes)
                                    : std::numeric_limits<double>::infinity();
  if (limits.max_memory_bytes > 0.0)
    bound = std::min(bound, limits.max_memory_bytes);
  return bound;
}

void enforceRunLimits(const RunPlan& plan, const LimitsConfig& limits, std::uint64_t physical_bytes)
{
  const std::string job = "job '" + plan.job_name + "': ";
  if (!(plan.machine_time_s <= limits.max_machine_time_s))
    throw ConfigError(
        job + "its machine time would be " + timeText(plan.machine_time_s) + " (program " +
        timeText(plan.program_duration_s) + " + filters " + timeText(2.0 * plan.filter_delay_s) + " + tail nc.tail_s " +
        timeText(plan.tail_s) +
        (plan.last_laser_off_s > plan.program_duration_s + 2.0 * plan.filter_delay_s
             ? "; the last laser-off at " + timeText(plan.last_laser_off_s) + " sets it: recipe.laser_off_delay_s"
             : std::string()) +
        "), above limits.max_machine_time_s = " + timeText(limits.max_machine_time_s) +
        "; check the job's speeds and dwells and the NC's delays, or raise limits.max_machine_time_s");
  if (!(plan.samples <= limits.max_samples))
    throw ConfigError(job + significantText(plan.samples, 4) + " samples (" + timeText(plan.machine_time_s) +
                      " at nc.period_s = " + significantText(plan.period_s, 4) + " s) exceed limits.max_samples = " +
                      significantText(limits.max_samples, 4) + "; raise nc.period_s or limits.max_samples");
  const double bound = memoryLimitBytes(limits, physical_bytes);
  const double total = plan.memory.total();
  if (!(total <= bound))
  {
    double part_bytes = 0.0;
    const std::string part = plan.memory.largestPart(&part_bytes);
    const std::string key = limits.max_memory_bytes > 0.0 && limits.max_memory_bytes <= bound
                                ? "limits.max_memory_bytes"
                                : "limits.max_memory_fraction (" + significantText(limits.max_memory_fraction, 3) +
                                      " of " + bytesText(static_cast<double>(physical_bytes)) + ")";
    throw ConfigError(job + "the run would need about " + bytesText(total) + " of memory, above " + bytesText(bound) +
                      " (" + key + "); the largest part: " + part + ", " + bytesText(part_bytes));
  }
}

std::string runPlanText(const RunPlan& p)
{
  char line[512];
  std::string out;
  std::snprintf(line, sizeof line,
                "plan: %s of machine time (program %s, tail %s), %.0f samples at %.3g us, map %lld x %lld px, "
                "~%.0f tiles touched (%.0f spilled to disk)\n",
                timeText(p.machine_time_s).c_str(), timeText(p.program_duration_s).c_str(), timeText(p.tail_s).c_str(),
                p.samples, p.period_s * 1e6, static_cast<long long>(p.map_width_px),
                static_cast<long long>(p.map_height_px), p.map_tiles_touched,
                p.map_tiles_touched - p.map_tiles_resident);
  out += line;
  std::snprintf(line, sizeof line, "plan: peak memory ~%s (largest: %s), wall time ~%s to %s (an estimate)\n",
                bytesText(p.memory.total()).c_str(), p.memory.largestPart().c_str(),
                timeText(0.5 * p.wall_time_s).c_str(), timeText(2.0 * p.wall_time_s).c_str());
  out += line;
  return out;
}
}  // namespace scanhead
