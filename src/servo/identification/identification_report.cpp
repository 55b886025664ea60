/// \file identification_report.cpp
#include "scanhead/servo/identification/identification_report.hpp"

#include <cmath>
#include <filesystem>
#include <sstream>

#include "scanhead/common/errors.hpp"
#include "scanhead/common/number_text.hpp"
#include "scanhead/common/text_file.hpp"

namespace scanhead
{
namespace
{
constexpr double kPi = 3.14159265358979323846;
using Complex = std::complex<double>;

double db(Complex v)
{
  return 20.0 * std::log10(std::abs(v));
}
double deg(double rad)
{
  return rad * 180.0 / kPi;
}
std::string num(double v)
{
  return sixDigitText(v);
}

/// A root as YAML: a number if real, else [re, im] (a complex-conjugate pole pair of i/U).
std::string complexText(Complex v)
{
  if (std::abs(v.imag()) <= 1e-12 * std::abs(v.real()))
    return num(v.real());
  return "[" + num(v.real()) + ", " + num(v.imag()) + "]";
}
}  // namespace

std::string bodeCsv(const IdentificationResult& r, const GalvoPlantParams& truth)
{
  std::ostringstream csv;
  csv << "frequency_hz,theta_meas_db,theta_meas_deg,theta_fit_db,theta_fit_deg,theta_true_db,theta_true_deg,"
         "theta_coherence,current_meas_db,current_meas_deg,current_fit_db,current_fit_deg,current_true_db,"
         "current_true_deg,current_coherence\n";
  const FrequencyResponse& t = r.theta_per_current;
  const FrequencyResponse& c = r.current_per_voltage;
  double last_f = 0.0;
  for (std::size_t k = 1; k < t.frequency_hz.size(); ++k)
  {
    const double f = t.frequency_hz[k];
    if (last_f > 0.0 && f < last_f * std::pow(10.0, 1.0 / 200.0))
      continue;  // at most 200 rows per decade
    last_f = f;
    const Complex gt = thetaPerCurrent(r.fitted, f), tt = trueThetaPerCurrent(truth, f);
    const Complex gc = currentPerVoltage(r.fitted, f), tc = trueCurrentPerVoltage(truth, f);
    csv << num(f) << ',' << num(db(t.response[k])) << ',' << num(deg(std::arg(t.response[k]))) << ',' << num(db(gt))
        << ',' << num(deg(std::arg(gt))) << ',' << num(db(tt)) << ',' << num(deg(std::arg(tt))) << ','
        << num(t.coherence[k]) << ',' << num(db(c.response[k])) << ',' << num(deg(std::arg(c.response[k]))) << ','
        << num(db(gc)) << ',' << num(deg(std::arg(gc))) << ',' << num(db(tc)) << ',' << num(deg(std::arg(tc))) << ','
        << num(c.coherence[k]) << '\n';
  }
  return csv.str();
}

std::string identificationReport(const GalvoPlantParams& truth, const IdentificationConfig& config,
                                 const std::string& out_dir, const PlotHook& plots)
{
  const IdentificationResult r = identifyGalvo(truth, config);
  const auto rel = [](double identified, double true_value) { return num(identified / true_value - 1.0); };
  std::ostringstream y;
  y << "# galvo identification, SPEC §3 / THESIS §2.2.1.2 (PRBS, H1 Welch, fit, eq. 2.13)\n"
    << "experiment:\n"
    << "  sample_period_s: " << num(config.sample_period_s) << "\n"
    << "  prbs_order: " << config.prbs.order << "\n"
    << "  prbs_clock_divider: " << config.prbs.clock_divider << "\n"
    << "  prbs_amplitude_v: " << num(config.prbs.amplitude) << "\n"
    << "  prbs_period_s: " << num(static_cast<double>(Prbs(config.prbs).periodSamples()) * config.sample_period_s)
    << "\n"
    << "  settle_periods: " << r.settle_periods << "\n"
    << "  averaged_periods: " << config.averaged_periods << "\n"
    << "  window: " << (config.window == SpectralWindow::Hann ? "hann" : "rectangular") << "\n"
    << "  position_loop_hz: " << num(config.position_loop_hz) << "\n"
    << "  position_gain_v_per_rad: " << num(r.position_gain_v_per_rad) << "\n"
    << "  ramp_rad_per_s: " << num(config.ramp_rad_per_s) << "\n"
    << "  friction: " << (config.zero_friction ? "zero  # Tp = Tc = 0 during the experiment" : "as_configured") << "\n"
    << "  samples: " << r.samples << "\n"
    << "  angle_range_rad: [" << num(r.angle_min_rad) << ", " << num(r.angle_max_rad) << "]\n"
    << "  velocity_sign_changes: " << r.velocity_sign_changes << "\n"
    << "  saturated_samples: " << r.saturated_samples << "\n"
    << "  frequency_resolution_hz: " << num(r.theta_per_current.frequency_hz[1]) << "\n"
    << "fit:\n"
    << "  G1_rad_per_as: " << num(r.fitted.g1_rad_per_as) << "  # true " << num(r.truth_forms.g1_rad_per_as) << "\n"
    << "  tau1_s: " << num(r.fitted.tau1_s) << "  # true " << num(r.truth_forms.tau1_s) << "\n"
    << "  G2_a_per_v: " << num(r.fitted.g2_a_per_v) << "  # true " << num(r.truth_forms.g2_a_per_v) << "\n"
    << "  tau2_plus_tau3_s: " << num(r.fitted.tau_sum_s) << "  # true " << num(r.truth_forms.tau_sum_s) << "\n"
    << "  tau2_times_tau3_s2: " << num(r.fitted.tau_product_s2) << "  # true " << num(r.truth_forms.tau_product_s2)
    << "\n"
    << "  tau2_s: " << complexText(r.fitted.tau2()) << "  # [re, im] if a complex pair; true "
    << complexText(r.truth_forms.tau2()) << "\n"
    << "  tau3_s: " << complexText(r.fitted.tau3()) << "  # true " << complexText(r.truth_forms.tau3()) << "\n"
    << "  theta_current_band_hz: [" << num(r.theta_per_current.frequency_hz[1]) << ", " << num(config.theta_fit_max_hz)
    << "]\n"
    << "  current_voltage_band_hz: [" << num(r.current_per_voltage.frequency_hz[1]) << ", "
    << num(config.current_fit_max_hz) << "]\n"
    << "  theta_current_rms_residual: " << num(r.theta_fit_rms_residual) << "  # RMS |G/Ĝ − 1|\n"
    << "  current_voltage_rms_residual: " << num(r.current_fit_rms_residual) << "\n"
    << "  theta_current_iterations: " << r.theta_fit_iterations << "\n"
    << "  current_voltage_iterations: " << r.current_fit_iterations << "\n";
  const auto block = [&](const char* name, const PhysicalParams& p) {
    y << name << ":\n"
      << "  R_ohm: " << num(p.resistance_ohm) << "\n"
      << "  L_h: " << num(p.inductance_h) << "\n"
      << "  Kc_nm_per_a: " << num(p.torque_constant_nm_per_a) << "\n"
      << "  B_nms: " << num(p.viscous_nms) << "\n"
      << "  Jeq_kgm2: " << num(p.inertia_kgm2) << "\n";
  };
  block("true", r.truth);
  block("identified", r.identified);
  y << "relative_error:\n"
    << "  R_ohm: " << rel(r.identified.resistance_ohm, r.truth.resistance_ohm) << "\n"
    << "  L_h: " << rel(r.identified.inductance_h, r.truth.inductance_h) << "\n"
    << "  Kc_nm_per_a: " << rel(r.identified.torque_constant_nm_per_a, r.truth.torque_constant_nm_per_a) << "\n"
    << "  B_nms: " << rel(r.identified.viscous_nms, r.truth.viscous_nms) << "\n"
    << "  Jeq_kgm2: " << rel(r.identified.inertia_kgm2, r.truth.inertia_kgm2) << "\n"
    << "bode_check:  # fitted forms vs the true plant (theta/i with its flexible mode)\n"
    << "  max_hz: " << num(config.bode_check_max_hz) << "\n"
    << "  theta_current_max_error_db: " << num(r.theta_bode_max_error_db) << "\n"
    << "  theta_current_max_error_deg: " << num(r.theta_bode_max_error_deg) << "\n"
    << "  current_voltage_max_error_db: " << num(r.current_bode_max_error_db) << "\n"
    << "  current_voltage_max_error_deg: " << num(r.current_bode_max_error_deg) << "\n";
  y << "warnings:";
  std::string warnings;
  if (r.theta_per_current.frequency_hz[1] > 1.0 / (2.0 * kPi * r.fitted.tau1_s))
    warnings +=
        "\n  - lowest line above the mechanical corner 1/(2 pi tau1): B and Jeq poorly determined; "
        "raise prbs.order or prbs.clock_divider";
  if (r.velocity_sign_changes > 0)
    warnings += "\n  - the rotor speed changed sign " + std::to_string(r.velocity_sign_changes) +
                " times: Coulomb friction made the plant nonlinear (raise ramp_rad_per_s or lower the amplitude)";
  if (r.saturated_samples > 0)
    warnings += "\n  - " + std::to_string(r.saturated_samples) + " samples beyond the supply voltage (saturated)";
  y << (warnings.empty() ? " []\n" : warnings + "\n");
  const std::string yaml = y.str();

  if (!out_dir.empty())
  {
    namespace fs = std::filesystem;
    std::error_code ec;
    fs::create_directories(out_dir, ec);
    if (ec)
      throw InputError(out_dir + ": cannot create (" + ec.message() + ")");
    writeTextFile(fs::path(out_dir) / "bode.csv", bodeCsv(r, truth));
    writeTextFile(fs::path(out_dir) / "identification.yaml", yaml);
    if (plots)
      plots(out_dir);
  }
  return yaml;
}
}  // namespace scanhead
