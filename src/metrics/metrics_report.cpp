#include "scanhead/metrics/metrics_report.hpp"
#include "scanhead/common/histogram.hpp"
#include "scanhead/common/number_text.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <sstream>

namespace scanhead
{
namespace
{
std::string errorStats(const ContourErrorStats& s)
{
  std::string bins;
  for (std::size_t i = 0; i <= ContourErrorStats::kBins; ++i)
    bins += (i > 0 ? ", " : "") + std::to_string(s.binCount(i));
  return "{points: " + std::to_string(s.count()) + ", share_under_10um: " + yamlNumber(s.shareUnder(10e-6)) +
         ", share_under_20um: " + yamlNumber(s.shareUnder(20e-6)) +
         ", share_under_30um: " + yamlNumber(s.shareUnder(30e-6)) + ", mean_m: " + yamlNumber(s.mean()) +
         ", p99_m: " + yamlNumber(s.quantileUpperBound(0.99)) + ", max_m: " + yamlNumber(s.max()) + ", counts_1um: [" +
         bins + "]}";
}

/// One definition: the shares over every marked point, then the split by kind of point.
std::string errorSplit(const ContourErrorSplit& s, const std::string& indent)
{
  return indent + "share_under_10um: " + yamlNumber(s.mark.shareUnder(10e-6)) + "\n" + indent +
         "share_under_20um: " + yamlNumber(s.mark.shareUnder(20e-6)) + "\n" + indent +
         "share_under_30um: " + yamlNumber(s.mark.shareUnder(30e-6)) + "\n" + indent + "mark: " + errorStats(s.mark) +
         "\n" + indent + "contour: " + errorStats(s.contour) + "\n" + indent + "hatch: " + errorStats(s.hatch) + "\n" +
         indent + "jump: " + errorStats(s.jump) + "\n";
}

std::string qualityYaml(const LayerQualityReport& q)
{
  std::string out;
  out += "contour_error:  # per commanded point (SPEC §5); shares over the marked points, then by kind\n";
  out += "  lag_s: " + fullPrecisionText(q.lag_s) + "  # same-instant pairing: actual sample k + round(lag/Ts)\n";
  out += "  commanded_points: " + std::to_string(q.commanded_points) + "\n";
  out += "  unmatched_points: " + std::to_string(q.unmatched_points) + "  # no same-instant sample (stream gap, end)\n";
  out += "  same_instant:  # THESIS §2.5.3.1: projection on the actual segments around the same-instant sample\n";
  out += errorSplit(q.same_instant, "    ");
  if (q.nearest_measured)
  {
    out += "  nearest_path:  # NC: distance to the whole actual path\n";
    out += errorSplit(q.nearest_path, "    ");
  }
  else
  {
    out += "  nearest_path: null  # not measured: more samples than energy.contour_max_samples\n";
  }
  out += "fill_rate: " + yamlNumber(q.fill_rate) + "  # THESIS §2.6: hatch cells of pitch = spot diameter reached\n";
  out += "fill: {pitch_m: " + fullPrecisionText(q.fill_pitch_m) +
         ", cells_to_fill: " + std::to_string(q.fill_cells_to_fill) +
         ", cells_reached: " + std::to_string(q.fill_cells_reached) +
         ", points_outside: " + std::to_string(q.fill_points_outside) + "}\n";
  out += "angle_error:  # Q_filt2 - Q_exp per axis over the program\n";
  out += "  x:\n" + histogramYaml(q.angle_error_x, "    ", 1e6, "urad");
  out += "  y:\n" + histogramYaml(q.angle_error_y, "    ", 1e6, "urad");
  out += "speed_profile:  # actual speed / programmed speed, laser-on mark samples\n";
  out += "  mean_ratio: " + yamlNumber(q.mark_speed_mean_ratio) + "\n";
  out += "  share_below_90pct: " + yamlNumber(q.mark_speed_ratio.fractionBelow(0.9)) + "\n";
  out += "  ratio:\n" + histogramYaml(q.mark_speed_ratio, "    ", 1.0, "1");
  return out;
}

std::string thermalYaml(const RunMetrics& m)
{
  if (!m.thermal_enabled)
    return "thermal: null  # off (thermal.enabled)\n";
  const MeltPoolStats& p = m.thermal_melt_pool;
  const ThermalEnergy& e = m.thermal_energy;
  auto steady = [&](double v) { return p.steady_steps > 0 ? fullPrecisionText(v) : std::string(".nan"); };
  std::string out = "thermal:  # PATH 2D layer model on the window thermal.start_s + duration_s\n";
  out += "  samples: " + std::to_string(m.thermal_samples) + "\n";
  out += "  steps: " + std::to_string(p.steps) + "\n";
  out += "  steady_steps: " + std::to_string(p.steady_steps) + "  # laser on for longer than thermal.settle_time_s\n";
  out += "  melt_pool_length_m: {steady_mean: " + steady(p.steady_length_mean_m) +
         ", steady_std: " + steady(p.steady_length_std_m) + ", max: " + fullPrecisionText(p.max_length_m) + "}\n";
  out += "  melt_pool_width_m: {steady_mean: " + steady(p.steady_width_mean_m) +
         ", steady_std: " + steady(p.steady_width_std_m) + ", max: " + fullPrecisionText(p.max_width_m) + "}\n";
  out += "  peak_rise_k: {steady_mean: " + steady(p.steady_peak_mean_k) + ", max: " + fullPrecisionText(p.max_peak_k) +
         "}\n";
  out += "  melted_area_m2: " + fullPrecisionText(m.thermal_melted_area_m2) + "\n";
  out += "  energy_j: {absorbed: " + fullPrecisionText(e.absorbed_j) + ", stored: " + fullPrecisionText(e.stored_j) +
         ", lost: " + fullPrecisionText(e.lost_j) + ", outside_window: " + fullPrecisionText(e.outside_j) +
         ", left_window: " + fullPrecisionText(e.left_window_j) + ", truncated: " + fullPrecisionText(e.truncated_j) +
         ", phase_switch: " + fullPrecisionText(e.phase_switch_j) + ", residual: " + fullPrecisionText(e.residual_j()) +
         "}\n";
  return out;
}

double relative(double value, double reference)
{
  return reference != 0.0 ? (value - reference) / reference : 0.0;
}

/// Appends fullPrecisionText(value) ("%.17g"): std::to_chars in general format with precision 17
/// writes the same characters (C++17 [charconv.to.chars]: as printf in the C locale), ~5x faster.
void appendFull(std::string& out, double value)
{
  char buffer[32];
  const std::to_chars_result r = std::to_chars(buffer, buffer + sizeof buffer, value, std::chars_format::general, 17);
  out.append(buffer, r.ptr);
}

void appendInteger(std::string& out, std::uint64_t value)
{
  char buffer[24];
  const std::to_chars_result r = std::to_chars(buffer, buffer + sizeof buffer, value);
  out.append(buffer, r.ptr);
}

void appendStats(std::string& out, const char* name, const CornerPathStats& s)
{
  out += name;
  out += "{min_speed_mps: ";
  appendFull(out, s.min_speed_mps);
  out += ", max_contour_error_m: ";
  appendFull(out, s.max_contour_error_m);
  out += "}\n";
}

/// The per-corner list (a whole layer has ~1e5 corners, ~400 bytes each): appended to one
/// string with to_chars, the same text as
/// ostream << fullPrecisionText(...) gave.
std::string cornersYaml(const std::vector<CornerReport>& corners)
{
  std::string out;
  out.reserve(corners.size() * 480);
  for (const CornerReport& c : corners)
  {
    out += "  - polyline: ";
    appendInteger(out, c.corner.polyline);
    out += "\n    vertex: ";
    appendInteger(out, c.corner.vertex);
    out += "\n    point_m: [";
    appendFull(out, c.corner.point.x());
    out += ", ";
    appendFull(out, c.corner.point.y());
    out += "]\n    angle_deg: ";
    appendFull(out, c.corner.angle_rad * 180.0 / M_PI);
    out += "\n    programmed_speed_mps: ";
    appendFull(out, c.corner.speed_mps);
    out += "\n";
    appendStats(out, "    setpoint: ", c.setpoint);
    appendStats(out, "    actual: ", c.actual);
    appendStats(out, "    theory: ", c.theory);
    out += "    energy_peak_jpm2: ";
    appendFull(out, c.energy_peak_jpm2);
    out += "\n";
  }
  return out;
}
}  // namespace

std::string metricsToYaml(const RunMetrics& m)
{
  std::ostringstream out;
  out << "job: \"" << m.job_name << "\"\n";
  if (!m.job_placement.empty())  // only a placed job has it: other runs read as before
    out << "placement: " << m.job_placement << "  # field = R(rotation)·file + offset\n";
  if (!m.warnings.empty())
  {
    out << "warnings:  # questionable but possible settings (run plan)\n";
    for (const std::string& w : m.warnings)
    {
      std::string quoted;
      for (const char c : w)
      {
        if (c == '"' || c == '\\')
          quoted += '\\';
        quoted += c;
      }
      out << "  - \"" << quoted << "\"\n";
    }
  }
  out << "samples: " << m.samples << "\n";
  out << "dropped_samples: " << m.dropped_samples << "\n";
  if (!m.complete)  // only an incomplete run has these lines: a complete one reads as before
  {
    out << "complete: false\n";
    out << "stream_gap: {streams: \"" << m.stream_gap.streams << "\", next_sample: " << m.stream_gap.next_sample
        << ", total_samples: " << m.stream_gap.total_samples
        << ", waited_s: " << fullPrecisionText(m.stream_gap.waited_s) << "}\n";
  }
  out << "duration_s: " << fullPrecisionText(m.duration_s) << "\n";
  out << "laser_on_time_s: " << fullPrecisionText(m.laser_on_time_s) << "\n";
  out << "commanded_energy_j: " << fullPrecisionText(m.commanded_energy_j) << "\n";
  out << "deposited_energy_j: " << fullPrecisionText(m.deposited_energy_j) << "\n";
  out << "energy_outside_map_j: " << fullPrecisionText(m.energy_outside_map_j) << "\n";
  out << "peak_energy_density_jpm2: " << fullPrecisionText(m.peak_energy_density_jpm2) << "\n";
  out << "layer_time_s: " << fullPrecisionText(m.quality.layer_time_s) << "  # the NC program, holds included\n";
  out << "peak_memory_bytes: " << m.peak_memory_bytes
      << "  # the energy stage's data at its largest (tiles, path, index, grids, track)\n";
  out << "energy_map: {tiles: " << m.map_tiles << ", tiles_spilled: " << m.map_tiles_spilled
      << ", spill_file_bytes: " << m.map_spill_file_bytes << "}\n";
  out << "nc: {capped_polylines: " << m.nc_program.capped_polylines << ", delay_holds: " << m.nc_program.delay_holds
      << ", polygon_holds: " << m.nc_program.polygon_holds
      << ", skywritten_corners: " << m.nc_program.skywritten_corners
      << ", added_time_s: " << fullPrecisionText(m.nc_program.added_time_s)
      << ", speed_cap_mps: " << yamlNumber(m.nc_speed_cap_mps)
      << ", filter_delay_s: " << fullPrecisionText(m.nc_filter_delay_s) << ", t1_s: " << fullPrecisionText(m.nc_t1_s)
      << ", t2_s: " << fullPrecisionText(m.nc_t2_s) << "}\n";
  out << "laser_early_samples: " << m.laser_early_samples << "\n";
  out << "laser_late_samples: " << m.laser_late_samples << "\n";
  out << "laser_misplaced_energy_j: " << fullPrecisionText(m.laser_misplaced_energy_j) << "\n";
  out << "laser_off_path_samples: " << m.laser_off_path_samples << "\n";
  out << "laser_max_off_path_m: " << yamlNumber(m.laser_max_off_path_m) << "\n";
  if (m.track_measured)
  {
    out << "track_energy: {median_jpm2: " << fullPrecisionText(m.track_median_jpm2)
        << ", peak_jpm2: " << fullPrecisionText(m.track_peak_jpm2)
        << ", mean_jpm2: " << fullPrecisionText(m.track_mean_jpm2) << ", stride: " << m.track_stride
        << ", peak_to_median: " << fullPrecisionText(m.track_peak_to_median)
        << ", min_to_median: " << fullPrecisionText(m.track_min_to_median) << ", peak_point_m: ["
        << fullPrecisionText(m.track_peak_point_m.x()) << ", " << fullPrecisionText(m.track_peak_point_m.y()) << "]}\n";
  }
  else
  {
    out << "track_energy: null  # not measured: no interior track\n";
  }
  out << "corner_energy: {mean_peak_to_track_mean: " << fullPrecisionText(m.corner_peak_to_track_mean)
      << ", max_peak_to_track_mean: " << fullPrecisionText(m.corner_peak_to_track_mean_max) << "}\n";
  out << qualityYaml(m.quality);
  out << thermalYaml(m);
  out << "corners:" << (m.corners.empty() ? " []\n" : "\n");
  out << cornersYaml(m.corners);
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
  std::snprintf(line, sizeof line,
                "energy: commanded %.6f J, deposited %.6f J (%+.4f %%), off the map %.3g J, peak %.4g J/mm^2\n",
                m.commanded_energy_j, m.deposited_energy_j,
                100.0 * relative(m.deposited_energy_j, m.commanded_energy_j), m.energy_outside_map_j,
                m.peak_energy_density_jpm2 * 1e-6);
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
  const LayerQualityReport& q = m.quality;
  std::snprintf(line, sizeof line, "layer: time %.6g s, fill rate %.2f %% (%llu of %llu cells of %.0f um)\n",
                q.layer_time_s, 100.0 * q.fill_rate, static_cast<unsigned long long>(q.fill_cells_reached),
                static_cast<unsigned long long>(q.fill_cells_to_fill), q.fill_pitch_m * 1e6);
  out += line;
  auto shares = [&](const char* name, const ContourErrorStats& s) {
    std::snprintf(line, sizeof line,
                  "  %-22s %8llu points: %6.2f %% < 10 um, %6.2f %% < 20 um, %6.2f %% < 30 um, max %.1f um\n", name,
                  static_cast<unsigned long long>(s.count()), 100.0 * s.shareUnder(10e-6), 100.0 * s.shareUnder(20e-6),
                  100.0 * s.shareUnder(30e-6), s.max() * 1e6);
    out += line;
  };
  out += "contour error of the marked points (and of the contours alone):\n";
  shares("same instant", q.same_instant.mark);
  if (q.same_instant.contour.count() > 0)
    shares("same instant, contours", q.same_instant.contour);
  if (q.nearest_measured)
  {
    shares("nearest path", q.nearest_path.mark);
    if (q.nearest_path.contour.count() > 0)
      shares("nearest path, contours", q.nearest_path.contour);
  }
  if (m.corners.empty())
    return out;
  out +=
      "corner  angle   speed  |        min speed [mm/s]             |       contour error [um]\n"
      "        [deg]   [mm/s] | setpoint  actual  theory  sp/theory | setpoint  actual  theory  sp/theory\n";
  constexpr std::size_t kShownCorners = 10;  // the rest are in metrics.yaml
  for (std::size_t i = 0; i < std::min(m.corners.size(), kShownCorners); ++i)
  {
    const CornerReport& c = m.corners[i];
    std::snprintf(
        line, sizeof line, "%-6zu  %6.2f  %6.0f | %8.1f  %6.1f  %6.1f  %+7.2f %% | %8.2f  %6.2f  %6.2f  %+7.2f %%\n", i,
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
