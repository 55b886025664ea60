/// \file galvo_identification.cpp
#include "scanhead/servo/identification/galvo_identification.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include <Eigen/Dense>

#include "scanhead/common/config_check.hpp"
#include "scanhead/common/errors.hpp"
#include "scanhead/common/levenberg_marquardt.hpp"
#include "scanhead/common/number_text.hpp"

namespace scanhead
{
namespace
{
constexpr double kPi = 3.14159265358979323846;
using Complex = std::complex<double>;

bool positiveFinite(double v)
{
  return v > 0.0 && std::isfinite(v);
}

double db(Complex v)
{
  return 20.0 * std::log10(std::abs(v));
}
double deg(double rad)
{
  return rad * 180.0 / kPi;
}

/// Bins of \p h with 0 < f ≤ max_hz and input power.
std::vector<std::size_t> fitBins(const FrequencyResponse& h, double max_hz)
{
  std::vector<std::size_t> bins;
  for (std::size_t k = 1; k < h.frequency_hz.size() && h.frequency_hz[k] <= max_hz; ++k)
    if (h.input_psd[k] > 0.0 && std::abs(h.response[k]) > 0.0)
      bins.push_back(k);
  return bins;
}

double median(std::vector<double> v)
{
  if (v.empty())
    return 0.0;
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

/// Fit of Ĝ over \p bins by the model \p model(params, f): LM on log parameters.
template <typename Model>
LevenbergMarquardtResult fitResponse(const FrequencyResponse& h, const std::vector<std::size_t>& bins,
                                     const Model& model, const Eigen::VectorXd& log_initial, double& rms_residual)
{
  std::vector<double> weight(bins.size());
  for (std::size_t m = 0; m < bins.size(); ++m)
    weight[m] = h.coherence[bins[m]] / std::sqrt(h.frequency_hz[bins[m]]);
  const auto residuals = [&](const Eigen::VectorXd& x) {
    Eigen::VectorXd r(2 * bins.size());
    for (std::size_t m = 0; m < bins.size(); ++m)
    {
      const std::size_t k = bins[m];
      const Complex e = weight[m] * (model(x, h.frequency_hz[k]) / h.response[k] - 1.0);
      r[2 * m] = e.real();
      r[2 * m + 1] = e.imag();
    }
    return r;
  };
  LevenbergMarquardtResult fit = levenbergMarquardt(residuals, log_initial, 200);
  double sum = 0.0;
  for (std::size_t k : bins)
    sum += std::norm(model(fit.x, h.frequency_hz[k]) / h.response[k] - 1.0);
  rms_residual = bins.empty() ? 0.0 : std::sqrt(sum / static_cast<double>(bins.size()));
  return fit;
}
}  // namespace

void IdentificationConfig::validate() const
{
  prbs.validate("identification.prbs");
  if (!positiveFinite(sample_period_s))
    failSetting("identification.sample_period_s", "> 0", sample_period_s);
  if (settle_periods < 1)
    failSetting("identification.settle_periods", ">= 1", settle_periods);
  if (averaged_periods < 1)
    failSetting("identification.averaged_periods", ">= 1", averaged_periods);
  if (!(position_loop_hz >= 0.0) || !std::isfinite(position_loop_hz))
    failSetting("identification.position_loop_hz", ">= 0", position_loop_hz);
  if (!std::isfinite(ramp_rad_per_s))
    failSetting("identification.ramp_rad_per_s", "finite", ramp_rad_per_s);
  const double nyquist = 0.5 / sample_period_s;
  const std::string band = "in (0, Nyquist " + sixDigitText(nyquist) + " Hz]";
  if (!positiveFinite(theta_fit_max_hz) || theta_fit_max_hz > nyquist)
    failSetting("identification.theta_fit_max_hz", band, theta_fit_max_hz);
  if (!positiveFinite(current_fit_max_hz) || current_fit_max_hz > nyquist)
    failSetting("identification.current_fit_max_hz", band, current_fit_max_hz);
  if (!positiveFinite(bode_check_max_hz))
    failSetting("identification.bode_check_max_hz", "> 0", bode_check_max_hz);
}

IdentificationResult identifyGalvo(const GalvoPlantParams& truth, const IdentificationConfig& config)
{
  config.validate();
  GalvoPlantParams plant_params = truth;
  if (config.zero_friction)
  {
    plant_params.offset_torque_nm = 0.0;
    plant_params.coulomb_torque_nm = 0.0;
  }
  Prbs prbs(config.prbs);
  const double t_s = config.sample_period_s;
  const std::size_t period = prbs.periodSamples();
  // Settle at least settle_periods and 10 time constants 1/(2π·position_loop_hz) of the loop, so
  // that its start transient (tiny excitation!) does not leak into the low-frequency lines.
  std::size_t settle = static_cast<std::size_t>(config.settle_periods);
  if (config.position_loop_hz > 0.0)
    settle = std::max(settle, static_cast<std::size_t>(std::ceil(10.0 / (2.0 * kPi * config.position_loop_hz) /
                                                                 (static_cast<double>(period) * t_s))));
  const std::size_t first = period * settle;
  const std::size_t total = first + period * static_cast<std::size_t>(config.averaged_periods);
  // The ramp is centred on angle 0 over the experiment: θref(t) = ramp·(t − total·T/2).
  const double ramp_start = -0.5 * config.ramp_rad_per_s * static_cast<double>(total) * t_s;
  GalvoPlant plant(plant_params);
  plant.reset(ramp_start);

  IdentificationResult result;
  // Nominal DC gain ω/U of the loaded motor, Kc/(BR + Kc²) [rad/s/V]: Kp puts the P loop's
  // crossover (≈ Kp · that gain, well below the mechanical pole) at position_loop_hz.
  const double kc = truth.torque_constant_nm_per_a;
  const double speed_per_volt = kc / (truth.viscous_nms * truth.resistance_ohm + kc * kc);
  const double kp = 2.0 * kPi * config.position_loop_hz / speed_per_volt;
  result.position_gain_v_per_rad = kp;

  const std::size_t count = total - first;
  std::vector<double> u(count), cur(count), dtheta(count);
  double theta_prev = 0.0, omega_prev = 0.0;
  result.angle_min_rad = result.angle_max_rad = plant.angle();
  for (std::size_t n = 0; n < total; ++n)
  {
    const double theta = plant.angle();
    const double omega = plant.rigidVelocity();
    const double volts = prbs.next() + kp * (ramp_start + config.ramp_rad_per_s * static_cast<double>(n) * t_s - theta);
    if (n >= first)
    {
      const std::size_t m = n - first;
      u[m] = volts;
      cur[m] = plant.current();
      dtheta[m] = theta - theta_prev;
      if (n > first && ((omega > 0.0) != (omega_prev > 0.0)))
        ++result.velocity_sign_changes;
      if (std::abs(volts) > truth.supply_voltage_v)
        ++result.saturated_samples;
    }
    result.angle_min_rad = std::min(result.angle_min_rad, theta);
    result.angle_max_rad = std::max(result.angle_max_rad, theta);
    theta_prev = theta;
    omega_prev = omega;
    plant.advance(volts, t_s);
  }
  result.samples = total;
  result.settle_periods = static_cast<int>(settle);

  WelchConfig welch;
  welch.segment_length = period;
  welch.overlap = 0;
  welch.window = config.window;
  welch.sample_period_s = t_s;
  result.current_per_voltage = estimateH1(u, cur, welch);
  result.theta_per_current = estimateH1(cur, dtheta, welch);
  for (std::size_t k = 0; k < result.theta_per_current.response.size(); ++k)
  {
    const Complex diff = 1.0 - std::polar(1.0, -2.0 * kPi * result.theta_per_current.frequency_hz[k] * t_s);
    Complex& g = result.theta_per_current.response[k];
    g = std::abs(diff) > 0.0 ? g / diff : Complex(0.0, 0.0);
  }

  // θ/i: initial guess from the asymptotes. High-frequency asymptote G1/(τ1 s²): K = G1/τ1 as the
  // median of |Ĝ|ω² over the top decade of the band; τ1 from the phase −90° − atan(ωτ1) at the bin
  // nearest −135°.
  const FrequencyResponse& hti = result.theta_per_current;
  const std::vector<std::size_t> tbins = fitBins(hti, config.theta_fit_max_hz);
  if (tbins.size() < 4)
    throw NumericalError("identifyGalvo: fewer than 4 excited bins below theta_fit_max_hz");
  std::vector<double> hf;
  double best = 1e300, tau1 = 0.0;
  for (std::size_t k : tbins)
  {
    const double w = 2.0 * kPi * hti.frequency_hz[k];
    if (hti.frequency_hz[k] >= 0.1 * config.theta_fit_max_hz)
      hf.push_back(std::abs(hti.response[k]) * w * w);
    const double phase = std::arg(hti.response[k]);  // in (−π, 0) for this form
    const double dist = std::abs(phase + 0.75 * kPi);
    if (dist < best)
    {
      best = dist;
      tau1 = std::tan(std::clamp(-phase - 0.5 * kPi, 1e-6, 0.5 * kPi - 1e-6)) / w;
    }
  }
  const double k_hf = median(hf);
  Eigen::VectorXd x0(2);
  x0 << std::log(k_hf * tau1), std::log(tau1);
  const auto theta_model = [](const Eigen::VectorXd& x, double f) {
    TransferForms m;
    m.g1_rad_per_as = std::exp(x[0]);
    m.tau1_s = std::exp(x[1]);
    return thetaPerCurrent(m, f);
  };
  const LevenbergMarquardtResult tfit = fitResponse(hti, tbins, theta_model, x0, result.theta_fit_rms_residual);
  result.fitted.g1_rad_per_as = std::exp(tfit.x[0]);
  result.fitted.tau1_s = std::exp(tfit.x[1]);
  result.theta_fit_iterations = tfit.iterations;

  // i/U with τ1 fixed, initial guess from the asymptotes: G2 from the low-frequency asymptote
  // G2|1 + jωτ1| at the lowest bin; π from the high-frequency asymptote G2τ1/(πω) (= 1/(Lω)) over
  // the top octave of the band; σ from |Ĝ| at ωn = 1/√π, where 1 + σs + πs² = jσωn exactly, so
  // |Ĝ(ωn)| ≈ G2τ1/σ (ωnτ1 ≫ 1).
  const FrequencyResponse& hiu = result.current_per_voltage;
  const std::vector<std::size_t> ibins = fitBins(hiu, config.current_fit_max_hz);
  if (ibins.size() < 4)
    throw NumericalError("identifyGalvo: fewer than 4 excited bins below current_fit_max_hz");
  const double tau1_fit = result.fitted.tau1_s;
  const double w0 = 2.0 * kPi * hiu.frequency_hz[ibins.front()];
  const double g2 = std::abs(hiu.response[ibins.front()]) / std::abs(Complex(1.0, w0 * tau1_fit));
  std::vector<double> top;
  for (std::size_t k : ibins)
    if (hiu.frequency_hz[k] >= 0.5 * config.current_fit_max_hz)
      top.push_back(std::abs(hiu.response[k]) * 2.0 * kPi * hiu.frequency_hz[k]);
  const double prod = g2 * tau1_fit / median(top);
  const double fn = 1.0 / (2.0 * kPi * std::sqrt(prod));
  std::size_t kn = ibins.front();
  for (std::size_t k : ibins)
    if (std::abs(hiu.frequency_hz[k] - fn) < std::abs(hiu.frequency_hz[kn] - fn))
      kn = k;
  const double sum = g2 * tau1_fit / std::abs(hiu.response[kn]);
  Eigen::VectorXd y0(3);
  y0 << std::log(g2), std::log(sum), std::log(prod);
  const auto current_model = [&](const Eigen::VectorXd& x, double f) {
    TransferForms m;
    m.tau1_s = tau1_fit;
    m.g2_a_per_v = std::exp(x[0]);
    m.tau_sum_s = std::exp(x[1]);
    m.tau_product_s2 = std::exp(x[2]);
    return currentPerVoltageZoh(m, f, t_s);
  };
  const LevenbergMarquardtResult ifit = fitResponse(hiu, ibins, current_model, y0, result.current_fit_rms_residual);
  result.fitted.g2_a_per_v = std::exp(ifit.x[0]);
  result.fitted.tau_sum_s = std::exp(ifit.x[1]);
  result.fitted.tau_product_s2 = std::exp(ifit.x[2]);
  result.current_fit_iterations = ifit.iterations;

  result.identified = recoverPhysicalParams(result.fitted);
  result.truth_forms = transferFormsOf(truth);
  result.truth.resistance_ohm = truth.resistance_ohm;
  result.truth.inductance_h = truth.inductance_h;
  result.truth.torque_constant_nm_per_a = truth.torque_constant_nm_per_a;
  result.truth.viscous_nms = truth.viscous_nms;
  result.truth.inertia_kgm2 = truth.inertia_kgm2;

  // Fitted forms against the true plant, 400 log-spaced points from the first bin to the check limit.
  const double f_lo = hti.frequency_hz[1], f_hi = config.bode_check_max_hz;
  for (int m = 0; m <= 400; ++m)
  {
    const double f = f_lo * std::pow(f_hi / f_lo, m / 400.0);
    const Complex et = thetaPerCurrent(result.fitted, f) / trueThetaPerCurrent(truth, f);
    const Complex ei = currentPerVoltage(result.fitted, f) / trueCurrentPerVoltage(truth, f);
    result.theta_bode_max_error_db = std::max(result.theta_bode_max_error_db, std::abs(db(et)));
    result.theta_bode_max_error_deg = std::max(result.theta_bode_max_error_deg, std::abs(deg(std::arg(et))));
    result.current_bode_max_error_db = std::max(result.current_bode_max_error_db, std::abs(db(ei)));
    result.current_bode_max_error_deg = std::max(result.current_bode_max_error_deg, std::abs(deg(std::arg(ei))));
  }
  return result;
}
}  // namespace scanhead
