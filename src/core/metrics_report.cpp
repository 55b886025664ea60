#include "scanhead/core/metrics_report.hpp"
#include "scanhead/core/number_text.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

namespace scanhead
{
namespace
{
std::string stats(const CornerPathStats& s)
{
  return "{min_speed_mps: " + fullPrecisionText(s.min_speed_mps) + ", max_contour_error_m: " + fullPrecisionText(s.max_contour_error_m) + "}";
}

/// Full precision, +infinity as YAML's .inf ("none": no speed cap, no mark to measure against).
std::string numberOrInfinity(double value)
{
  return std::isinf(value) && value > 0.0 ? std::string(".inf") : fullPrecisionText(value);
}

double relative(double value, double reference)
{
  return reference != 0.0 ? (value - reference) / reference : 0.0;
}
}  // namespace

std::string metricsToYaml(const RunMetrics& m)
{
  std::ostringstream out;
  out << "job: \"" << m.job_name << "\"\n";
  out << "samples: " << m.samples << "\n";
  out << "dropped_samples: " << m.dropped_samples << "\n";
  out << "duration_s: " << fullPrecisionText(m.duration_s) << "\n";
  out << "laser_on_time_s: " << fullPrecisionText(m.laser_on_time_s) << "\n";
  out << "commanded_energy_j: " << fullPrecisionText(m.commanded_energy_j) << "\n";
  out << "deposited_energy_j: " << fullPrecisionText(m.deposited_energy_j) << "\n";
  out << "energy_outside_map_j: " << fullPrecisionText(m.energy_outside_map_j) << "\n";
  out << "peak_energy_density_jpm2: " << fullPrecisionText(m.peak_energy_density_jpm2) << "\n";
  out << "nc: {capped_polylines: " << m.nc_program.capped_polylines << ", delay_holds: " << m.nc_program.delay_holds
      << ", polygon_holds: " << m.nc_program.polygon_holds << ", skywritten_corners: " << m.nc_program.skywritten_corners
      << ", added_time_s: " << fullPrecisionText(m.nc_program.added_time_s)
      << ", speed_cap_mps: " << numberOrInfinity(m.nc_speed_cap_mps)
      << ", filter_delay_s: " << fullPrecisionText(m.nc_filter_delay_s) << ", t1_s: " << fullPrecisionText(m.nc_t1_s)
      << ", t2_s: " << fullPrecisionText(m.nc_t2_s) << "}\n";
  out << "laser_early_samples: " << m.laser_early_samples << "\n";
  out << "laser_late_samples: " << m.laser_late_samples << "\n";
  out << "laser_misplaced_energy_j: " << fullPrecisionText(m.laser_misplaced_energy_j) << "\n";
  out << "laser_off_path_samples: " << m.laser_off_path_samples << "\n";
  out << "laser_max_off_path_m: "
      << numberOrInfinity(m.laser_max_off_path_m) << "\n";
  if (m.track_measured)
  {
    out << "track_energy: {median_jpm2: " << fullPrecisionText(m.track_median_jpm2)
        << ", peak_jpm2: " << fullPrecisionText(m.track_peak_jpm2)
        << ", peak_to_median: " << fullPrecisionText(m.track_peak_to_median)
        << ", min_to_median: " << fullPrecisionText(m.track_min_to_median) << ", peak_point_m: ["
        << fullPrecisionText(m.track_peak_point_m.x()) << ", " << fullPrecisionText(m.track_peak_point_m.y()) << "]}\n";
  }
  else
  {
    out << "track_energy: null  # not measured: no interior track, or more laser-on samples than energy.track_max_samples\n";
  }
  out << "corners:" << (m.corners.empty() ? " []\n" : "\n");
  for (const CornerReport& c : m.corners)
  {
    out << "  - polyline: " << c.corner.polyline << "\n";
    out << "    vertex: " << c.corner.vertex << "\n";
    out << "    point_m: [" << fullPrecisionText(c.corner.point.x()) << ", " << fullPrecisionText(c.corner.point.y()) << "]\n";
    out << "    angle_deg: " << fullPrecisionText(c.corner.angle_rad * 180.0 / M_PI) << "\n";
    out << "    programmed_speed_mps: " << fullPrecisionText(c.corner.speed_mps) << "\n";
    out << "    setpoint: " << stats(c.setpoint) << "\n";
    out << "    actual: " << stats(c.actual) << "\n";
    out << "    theory: " << stats(c.theory) << "\n";
  }
  return out.str();
}

std::string metricsTable(const RunMetrics& m)
{
  char line[256];
  std::string out;
  std::snprintf(line, sizeof line, "job %s: %llu samples (%llu dropped), %.3f ms, laser on %.3f ms\n",
                m.job_name.c_str(), static_cast<unsigned long long>(m.samples),
                static_cast<unsigned long long>(m.dropped_samples), m.duration_s * 1e3, m.laser_on_time_s * 1e3);
  out += line;
  std::snprintf(line, sizeof line, "energy: commanded %.6f J, deposited %.6f J (%+.4f %%), off the map %.3g J, peak %.4g J/mm^2\n",
                m.commanded_energy_j, m.deposited_energy_j, 100.0 * relative(m.deposited_energy_j, m.commanded_energy_j),
                m.energy_outside_map_j, m.peak_energy_density_jpm2 * 1e-6);
  out += line;
  std::snprintf(line, sizeof line,
                "laser: %llu samples on before the spot reached its mark, %llu after it left (%.3g J); "
                "%llu on farther than the tolerance from any mark (max %.1f um)\n",
                static_cast<unsigned long long>(m.laser_early_samples),
                static_cast<unsigned long long>(m.laser_late_samples), m.laser_misplaced_energy_j,
                static_cast<unsigned long long>(m.laser_off_path_samples), m.laser_max_off_path_m * 1e6);
  out += line;
  if (m.track_measured)
  {
    std::snprintf(line, sizeof line,
                  "track energy: straight level %.4g J/mm^2, peak %.4g J/mm^2 (x%.3f) at (%.3f, %.3f) mm, "
                  "lowest x%.3f\n",
                  m.track_median_jpm2 * 1e-6, m.track_peak_jpm2 * 1e-6, m.track_peak_to_median,
                  m.track_peak_point_m.x() * 1e3, m.track_peak_point_m.y() * 1e3, m.track_min_to_median);
    out += line;
  }
  if (m.corners.empty())
    return out;
  out += "corner  angle   speed  |        min speed [mm/s]             |       contour error [um]\n"
         "        [deg]   [mm/s] | setpoint  actual  theory  sp/theory | setpoint  actual  theory  sp/theory\n";
  constexpr std::size_t kShownCorners = 10;  // the rest are in metrics.yaml
  for (std::size_t i = 0; i < std::min(m.corners.size(), kShownCorners); ++i)
  {
    const CornerReport& c = m.corners[i];
    std::snprintf(line, sizeof line, "%-6zu  %6.2f  %6.0f | %8.1f  %6.1f  %6.1f  %+7.2f %% | %8.2f  %6.2f  %6.2f  %+7.2f %%\n", i,
                  c.corner.angle_rad * 180.0 / M_PI, c.corner.speed_mps * 1e3, c.setpoint.min_speed_mps * 1e3,
                  c.actual.min_speed_mps * 1e3, c.theory.min_speed_mps * 1e3,
                  100.0 * relative(c.setpoint.min_speed_mps, c.theory.min_speed_mps), c.setpoint.max_contour_error_m * 1e6,
                  c.actual.max_contour_error_m * 1e6, c.theory.max_contour_error_m * 1e6,
                  100.0 * relative(c.setpoint.max_contour_error_m, c.theory.max_contour_error_m));
    out += line;
  }
  if (m.corners.size() > kShownCorners)
    out += "... " + std::to_string(m.corners.size() - kShownCorners) +
           " more corners in metrics.yaml (the closed forms assume legs longer than the filters)\n";
  return out;
}

std::string ncLimitsLine(const NcStats& stats, const NcConfig& config)
{
  char line[320];
  std::snprintf(line, sizeof line,
                "nc: Q_filt2 max |accel| %.4g / %.4g rad/s^2 (x %.3f of the limit), max |jerk| %.4g / %.4g rad/s^3 "
                "(x %.3f); samples over: %llu accel, %llu jerk\n",
                stats.max_accel_radps2.x(), stats.max_accel_radps2.y(),
                stats.max_accel_radps2.maxCoeff() / config.max_joint_accel_radps2, stats.max_jerk_radps3.x(),
                stats.max_jerk_radps3.y(), stats.max_jerk_radps3.maxCoeff() / config.max_joint_jerk_radps3,
                static_cast<unsigned long long>(stats.samples_over_accel),
                static_cast<unsigned long long>(stats.samples_over_jerk));
  return line;
}
}  // namespace scanhead
