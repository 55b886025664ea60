#include "scanhead/core/energy_stage.hpp"

#include <cmath>

#include "scanhead/core/galvo_servo.hpp"
#include "scanhead/core/track_energy.hpp"

namespace scanhead
{
namespace
{
constexpr std::size_t kMaxTraceRows = 20000;  // plots need no more; bounds memory on long jobs

EnergyAccumulator makeAccumulator(const ChainConfig& config, const Job& job)
{
  Eigen::Vector2d lo, hi;
  jobMapBounds(job, config.energy.map_margin_m, lo, hi);
  return EnergyAccumulator(config.energy, lo, hi);
}

CornerTracker makeCornerTracker(const ChainConfig& config, const NcInterpolator& nc)
{
  const double servo_delay = GalvoServo(config.servo, config.nc.period_s).lowFrequencyDelay().maxCoeff();
  const double filter_delay = nc.stats().filter_delay_s;
  return CornerTracker(findCorners(nc.program().timeline, config.energy.corner_min_angle_deg * M_PI / 180.0),
                       filter_delay, filter_delay + servo_delay);
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

EnergyStage::EnergyStage(const ChainConfig& config, const Job& job, const NcInterpolator& nc)
  : config_(config)
  , job_name_(job.name)
  , accumulator_(makeAccumulator(config, job))
  , corners_(makeCornerTracker(config, nc))
  , settling_(nc.program(), nc.stats().gate_shift_s, nc.stats().filter_delay_s, config.energy.laser_path_tolerance_m)
  , placement_(job, config.energy.laser_path_tolerance_m)
  , trace_(nc.totalSamples(), kMaxTraceRows)
  , nc_stats_(nc.stats())
{
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
  counter_.process(chunk);
  accumulator_.process(chunk);
  corners_.process(chunk);
  settling_.process(chunk);
  placement_.add(chunk);
  trace_.process(chunk);
  keepTrack(chunk);
}

void EnergyStage::keepTrack(const SpotChunk& chunk)
{
  // Laser-on samples for the track energy profile, each burst closed by one laser-off sample;
  // beyond the cap the profile is not measured (memory stays bounded on long jobs).
  if (track_overflow_)
    return;
  for (const SpotSample& s : chunk.samples)
  {
    const bool on = s.power_w > 0.0;
    if (on || (!track_.empty() && track_.back().power_w > 0.0))
      track_.push_back(s);
  }
  if (track_.size() > config_.energy.track_max_samples)
  {
    track_overflow_ = true;
    std::vector<SpotSample>().swap(track_);
  }
}

RunMetrics EnergyStage::finish()
{
  accumulator_.finish();
  RunMetrics m;
  m.job_name = job_name_;
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
  if (!track_overflow_)
  {
    const TrackEnergyProfile track =
        trackEnergyProfile(accumulator_.map(), track_, config_.energy.track_exclude_ends_m, &mark_ends_);
    m.track_measured = track.interior_samples > 0;
    m.track_median_jpm2 = track.median_jpm2;
    m.track_peak_jpm2 = track.peak_jpm2;
    m.track_peak_to_median = track.peakToMedian();
    m.track_min_to_median = track.minToMedian();
    m.track_peak_point_m = track.peak_point_m;
  }
  return m;
}
}  // namespace scanhead
