#include "scanhead/chain/energy_stage.hpp"

#include <algorithm>
#include <cmath>
#include <future>
#include <stdexcept>

#include "scanhead/energy/map_regions.hpp"
#include "scanhead/energy/track_energy.hpp"

namespace scanhead
{
namespace
{
constexpr std::size_t kMaxTraceRows = 20000;       // plots need no more; bounds memory on long jobs
constexpr std::size_t kParallelChunkSamples = 64;  // smaller chunks run their trackers inline

EnergyAccumulator makeAccumulator(const ChainConfig& config, const Job& job)
{
  Eigen::Vector2d lo, hi;
  jobMapBounds(job, config.energy.map_margin_m, lo, hi);
  return EnergyAccumulator(config.energy, lo, hi);
}

double actualDelay(const NcPlan& plan)
{
  if (!std::isfinite(plan.servo_delay_s))
  {
    throw std::invalid_argument("energy stage: the NC plan of job '" + plan.job_name +
                                "' has no servo delay (build the NC with the servo model)");
  }
  return plan.actualDelay();
}

CornerTracker makeCornerTracker(const ChainConfig& config, const NcPlan& plan, double actual_delay_s)
{
  return CornerTracker(findCorners(plan.program.timeline, config.energy.corner_min_angle_deg * M_PI / 180.0),
                       plan.filter_delay_s, actual_delay_s);
}

LayerQuality makeLayerQuality(const ChainConfig& config, const Job& job, const NcPlan& plan, double actual_delay_s)
{
  const double lag = config.energy.contour_lag_s >= 0.0 ? config.energy.contour_lag_s : actual_delay_s;
  Eigen::Vector2d lo, hi;
  jobMapBounds(job, config.energy.map_margin_m, lo, hi);
  return LayerQuality(config.energy, plan.program.timeline, job, lag, plan.total_samples, lo, hi);
}
}  // namespace

void jobMapBounds(const Job& job, double margin_m, Eigen::Vector2d& min_corner, Eigen::Vector2d& max_corner)
{
  min_corner = Eigen::Vector2d::Constant(INFINITY);
  max_corner = Eigen::Vector2d::Constant(-INFINITY);
  for (const Polyline& line : job.polylines)
    for (const Eigen::Vector2d& p : line.points)
    {
      min_corner = min_corner.cwiseMin(p);
      max_corner = max_corner.cwiseMax(p);
    }
  min_corner.array() -= margin_m;
  max_corner.array() += margin_m;
}

EnergyStage::EnergyStage(const ChainConfig& config, const Job& job, const NcPlan& plan)
  : config_(config)
  , job_name_(job.name)
  , job_placement_(job.placement.placed() ? job.placement.yaml() : std::string())
  , actual_delay_s_(actualDelay(plan))
  , accumulator_(makeAccumulator(config, job))
  , corners_(makeCornerTracker(config, plan, actual_delay_s_))
  , settling_(plan.program, plan.gate_shift_s, plan.filter_delay_s, config.energy.laser_path_tolerance_m)
  , placement_(job, config.energy.laser_path_tolerance_m)
  , trace_(plan.total_samples, kMaxTraceRows)
  , nc_stats_(ncStatsOf(plan))
  , quality_(makeLayerQuality(config, job, plan, actual_delay_s_))
  , export_crops_(exportCrops(job, config.energy))
{
  // A crop that misses the map is a setting error: said now, not after the run.
  const TiledEnergyMap& map = accumulator_.map();
  requireRegionsOnMap(parseMapRegions(config.energy.crop_regions), map.origin(),
                      map.origin() + map.pixel() * Eigen::Vector2d(static_cast<double>(map.width()),
                                                                   static_cast<double>(map.height())));
  if (config.thermal.enabled)
    thermal_ = std::make_unique<ThermalLayer>(config.thermal.model);
  for (const Polyline& line : job.polylines)
  {
    if (line.type == PolylineType::Mark && !line.points.empty())
    {
      mark_ends_.push_back(line.points.front());
      mark_ends_.push_back(line.points.back());
    }
  }
}

void EnergyStage::process(const SpotChunk& chunk)
{
  // The map and the trackers share nothing but the (read-only) chunk: the trackers run on a second
  // core while this one deposits the energy, and are joined before returning (so results do not
  // depend on the scheduling, and an exception in either reaches the caller).
  auto track = [this, &chunk] {
    counter_.process(chunk);
    corners_.process(chunk);
    settling_.process(chunk);
    placement_.add(chunk);
    trace_.process(chunk);
    keepTrack(chunk);
    quality_.process(chunk);
    if (thermal_)
      feedThermal(chunk);
  };
  if (config_.stream.threads < 2 || chunk.samples.size() < kParallelChunkSamples)
  {
    track();  // one thread asked for, or a thread would cost more than it saves
    accumulator_.process(chunk);
    return;
  }
  if (!side_)
    side_ = std::make_unique<SideThread>();
  // This thread merges the chunk's samples into strokes; both threads then weigh them (the side thread once the
  // trackers are done: the energy's weights are most of the work). The weighed batch is set aside and added to the
  // map by this thread during the next chunk, while the side thread runs that chunk's trackers: batches reach the map
  // in stream order, so the map is the same floats as on one thread.
  try
  {
    accumulator_.stage(chunk);
  }
  catch (...)
  {
    // As on one thread: the trackers still see the chunk (their own error is secondary) and the strokes merged
    // before the error are drawn.
    try
    {
      track();
    }
    catch (...)
    {
    }
    accumulator_.weighStaged();
    accumulator_.applyStaged();
    throw;
  }
  side_->start([this, &track] {
    track();
    accumulator_.weighStaged();
  });
  std::exception_ptr weigh_error, side_error;
  try
  {
    accumulator_.applyReady();  // the previous chunk's strokes
    accumulator_.weighStaged();
  }
  catch (...)
  {
    weigh_error = std::current_exception();
  }
  try
  {
    side_->wait();  // the trackers read the chunk: they finish before it goes
  }
  catch (...)
  {
    side_error = std::current_exception();
  }
  if (weigh_error)
    std::rethrow_exception(weigh_error);  // (out of memory, a spill file error) the batches wait
  if (side_error)
  {
    accumulator_.applyStaged();  // as on one thread: the map holds every stroke merged before the error
    std::rethrow_exception(side_error);
  }
  accumulator_.retireStaged();
}

void EnergyStage::feedThermal(const SpotChunk& chunk)
{
  // The samples of the thermal time window only (the model skips indices it has seen, and treats
  // a gap as laser off).
  std::size_t first = 0;
  while (first < chunk.samples.size() && !config_.thermal.covers(chunk.first_index + first, chunk.period_s))
    ++first;
  std::size_t end = first;
  while (end < chunk.samples.size() && config_.thermal.covers(chunk.first_index + end, chunk.period_s))
    ++end;
  if (first == end)
    return;
  SpotChunk part;
  part.first_index = chunk.first_index + first;
  part.period_s = chunk.period_s;
  part.samples.assign(chunk.samples.begin() + static_cast<std::ptrdiff_t>(first),
                      chunk.samples.begin() + static_cast<std::ptrdiff_t>(end));
  thermal_->process(part);
  thermal_samples_ += part.samples.size();
}

void EnergyStage::keepTrack(const SpotChunk& chunk)
{
  // Laser-on samples for the track energy profile, each burst closed by one laser-off sample.
  // Memory stays bounded: past energy.track_max_samples every other laser-on sample is dropped and
  // the stride doubles (decided sample by sample, so chunking does not change what is kept).
  for (const SpotSample& s : chunk.samples)
  {
    if (s.power_w > 0.0)
    {
      if (track_seen_++ % track_stride_ != 0)
        continue;
      track_.push_back(s);
      if (track_.size() > config_.energy.track_max_samples)
        thinTrack();
    }
    else if (!track_.empty() && track_.back().power_w > 0.0)
    {
      track_.push_back(s);
    }
  }
  track_peak_bytes_ = std::max(track_peak_bytes_, track_.capacity() * sizeof(SpotSample));
}

void EnergyStage::thinTrack()
{
  // The i-th laser-on entry is laser-on sample i·stride: keep the even ones (stride → 2·stride).
  std::size_t kept = 0, on = 0;
  for (const SpotSample& s : track_)
  {
    if (s.power_w > 0.0 && on++ % 2 != 0)
      continue;
    if (s.power_w <= 0.0 && (kept == 0 || track_[kept - 1].power_w <= 0.0))
      continue;  // a burst left with no sample needs no closing sample
    track_[kept++] = s;
  }
  track_.resize(kept);
  track_stride_ *= 2;
}

std::shared_ptr<const EnergyMapViews> EnergyStage::mapViews() const
{
  if (!views_)
    views_ = std::make_shared<const EnergyMapViews>(readEnergyMapViews(accumulator_.map(), export_crops_));
  return views_;
}

RunMetrics EnergyStage::finish()
{
  views_.reset();  // a map still growing is never shown
  // The layer metrics' last pass (the nearest-path index over the whole path) needs no map: it runs
  // on the second core while this one reads the map for the energy figures.
  auto quality = std::async(config_.stream.threads < 2 ? std::launch::deferred : std::launch::async,
                            [this] { return quality_.finish(static_cast<unsigned>(config_.stream.threads)); });
  accumulator_.finish();
  RunMetrics m;
  m.job_name = job_name_;
  m.job_placement = job_placement_;
  m.samples = counter_.samples();
  m.dropped_samples = counter_.dropped();
  m.duration_s = static_cast<double>(counter_.samples()) * config_.nc.period_s;
  m.laser_on_time_s = counter_.laserOnTime();
  m.commanded_energy_j = counter_.commandedEnergy();
  m.deposited_energy_j = accumulator_.map().totalEnergy();
  m.energy_outside_map_j = accumulator_.energyOutsideMap();
  m.peak_energy_density_jpm2 = accumulator_.map().peak();
  m.corners = corners_.reports(config_.nc.fir_t1_s, config_.nc.fir_t2_s);
  m.nc_program = nc_stats_.program;
  m.nc_speed_cap_mps = nc_stats_.speed_cap_mps;
  m.nc_filter_delay_s = nc_stats_.filter_delay_s;
  m.nc_t1_s = nc_stats_.longest_t1_s;
  m.nc_t2_s = nc_stats_.longest_t2_s;
  const LaserSettlingCounts& settling = settling_.counts();
  m.laser_early_samples = settling.early_samples;
  m.laser_late_samples = settling.late_samples;
  m.laser_misplaced_energy_j = settling.early_energy_j + settling.late_energy_j;
  m.laser_off_path_samples = placement_.counts().off_path_samples;
  m.laser_max_off_path_m = placement_.counts().max_distance_m;
  // The map's figures before its tiles are released below (its memory, and the spill file as the stream left it).
  const TiledEnergyMap& map = accumulator_.map();
  const std::size_t map_peak_bytes = map.peakResidentBytes();
  m.map_tiles = map.tilesTouched();
  m.map_tiles_spilled = map.tilesSpilled();
  m.map_spill_file_bytes = map.spillFileBytes();
  // One pass over the map in tile order reads every tile once (one read of the spill file): the results' overview
  // and crops, and from the same tiles the track's energy and the corner peaks. It needs no tile cache: a map that
  // spilled gives its tiles' memory back first (on the THESIS layer, 256 MB the pass's own data and the nearest-path
  // index on the other core then use). On one thread the views are read here too (before the metrics' last pass).
  if (map.tilesSpilled() > 0)
    map.releaseTiles();
  std::vector<Eigen::Vector2d> corner_points;
  std::vector<double> corner_radii;
  for (const CornerReport& c : m.corners)
  {
    // The actual path cuts the corner: look as far as it passed from it, plus a spot radius.
    const double cut = std::isfinite(c.actual.max_contour_error_m) ? c.actual.max_contour_error_m : 0.0;
    corner_points.push_back(c.corner.point);
    corner_radii.push_back(cut + 0.5 * config_.energy.spot_diameter_m);
  }
  DiscPeakSampler corner_sampler(map, corner_points, corner_radii);
  TrackEnergySampler track_sampler(map, track_, config_.energy.track_exclude_ends_m, &mark_ends_);
  track_ = {};  // its last reader took the interior spots (16 B of the 80 B a sample)
  auto views = std::make_shared<EnergyMapViews>(
      readEnergyMapViews(map, export_crops_, [&](std::int64_t tile, const float* data) {
        track_sampler.serve(tile, data);
        corner_sampler.serve(tile, data);
      }));
  const TrackEnergyProfile track = track_sampler.finish(map);
  const std::vector<double> corner_peaks = corner_sampler.finish(map);
  m.track_measured = track.interior_samples > 0;
  m.track_median_jpm2 = track.median_jpm2;
  m.track_mean_jpm2 = track.mean_jpm2;
  m.track_peak_jpm2 = track.peak_jpm2;
  m.track_peak_to_median = track.peakToMedian();
  m.track_min_to_median = track.minToMedian();
  m.track_peak_point_m = track.peak_point_m;
  m.track_stride = track_stride_;
  double ratio_sum = 0.0;
  for (std::size_t i = 0; i < m.corners.size(); ++i)
  {
    CornerReport& c = m.corners[i];
    c.energy_peak_jpm2 = corner_peaks[i];
    if (track.mean_jpm2 > 0.0)
    {
      const double ratio = c.energy_peak_jpm2 / track.mean_jpm2;
      ratio_sum += ratio;
      m.corner_peak_to_track_mean_max = std::max(m.corner_peak_to_track_mean_max, ratio);
    }
  }
  if (track.mean_jpm2 > 0.0 && !m.corners.empty())
    m.corner_peak_to_track_mean = ratio_sum / static_cast<double>(m.corners.size());
  if (!m.corners.empty())
  {
    // The results zoom on the corner with the highest energy peak (the first of equals): crops/worst_corner.*, at
    // full resolution, four spot diameters around the corner beyond what the path cut from it (a few tiles, read now
    // that the peaks are known).
    const CornerReport& worst = *std::max_element(
        m.corners.begin(), m.corners.end(),
        [](const CornerReport& a, const CornerReport& b) { return a.energy_peak_jpm2 < b.energy_peak_jpm2; });
    const double cut = std::isfinite(worst.actual.max_contour_error_m) ? worst.actual.max_contour_error_m : 0.0;
    const Eigen::Vector2d half = Eigen::Vector2d::Constant(cut + 4.0 * config_.energy.spot_diameter_m);
    export_crops_.push_back({"worst_corner", worst.corner.point - half, worst.corner.point + half});
    views->crops.push_back(readCropView(map, export_crops_.back()));
  }
  views_ = std::move(views);
  m.quality = quality.get();
  if (thermal_)
  {
    thermal_->finish();
    m.thermal_enabled = true;
    m.thermal_samples = thermal_samples_;
    m.thermal_melt_pool = thermal_->stats();
    m.thermal_energy = thermal_->energy();
    m.thermal_melted_area_m2 = thermal_->meltedArea();
  }
  m.peak_memory_bytes = map_peak_bytes + m.quality.memory_bytes + track_peak_bytes_;
  return m;
}
}  // namespace scanhead
