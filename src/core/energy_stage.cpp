#include "scanhead/core/energy_stage.hpp"

#include <cmath>

#include "scanhead/core/galvo_servo.hpp"

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

CornerTracker makeCornerTracker(const ChainConfig& config, const Job& job)
{
  const double servo_delay = GalvoServo(config.servo, config.nc.period_s).lowFrequencyDelay().maxCoeff();
  return CornerTracker(findCorners(job, config.energy.corner_min_angle_deg * M_PI / 180.0,
                                   config.nc.implicit_jump_speed_mps),
                       config.nc.filterDelay(), config.nc.filterDelay() + servo_delay);
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

EnergyStage::EnergyStage(const ChainConfig& config, const Job& job, std::uint64_t total_samples)
  : config_(config)
  , job_name_(job.name)
  , accumulator_(makeAccumulator(config, job))
  , corners_(makeCornerTracker(config, job))
  , trace_(total_samples, kMaxTraceRows)
{
}

void EnergyStage::process(const SpotChunk& chunk)
{
  counter_.process(chunk);
  accumulator_.process(chunk);
  corners_.process(chunk);
  trace_.process(chunk);
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
  return m;
}
}  // namespace scanhead
