/// \file galvo_identification.cpp
#include "scanhead/servo/identification/galvo_identification.hpp"
#include "scanhead/common/text_file.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <sstream>

#include <Eigen/Dense>

#include "scanhead/common/package_path.hpp"
#include "scanhead/common/config_check.hpp"
#include "scanhead/common/errors.hpp"

namespace scanhead
{
namespace
{
constexpr double kPi = 3.14159265358979323846;
using Complex = std::complex<double>;

bool positiveFinite(double v) { return v > 0.0 && std::isfinite(v); }

/// Levenberg–Marquardt (Marquardt's diagonal scaling) with a central-difference Jacobian.
struct LmResult
{
  Eigen::VectorXd x;
  double cost = 0.0;  ///< Σ r²
  int iterations = 0;
};

template <typename Residuals>
LmResult levenbergMarquardt(const Residuals& residuals, Eigen::VectorXd x, int max_iterations)
{
  const Eigen::Index n = x.size();
  Eigen::VectorXd r = residuals(x);
  double cost = r.squaredNorm();
  double lambda = 1e-3;
  int it = 0;
  bool converged = false;
  while (!converged && it < max_iterations)
  {
    ++it;
    Eigen::MatrixXd jac(r.size(), n);
    for (Eigen::Index j = 0; j < n; ++j)
    {
      const double h = 1e-6 * std::max(1.0, std::abs(x[j]));
      Eigen::VectorXd xp = x, xm = x;
      xp[j] += h;
      xm[j] -= h;
      jac.col(j) = (residuals(xp) - residuals(xm)) / (2.0 * h);
    }
    const Eigen::MatrixXd a = jac.transpose() * jac;
    const Eigen::VectorXd g = jac.transpose() * r;
    bool improved = false;
    Eigen::VectorXd step;
    while (lambda < 1e12)
    {
      Eigen::MatrixXd damped = a;
      for (Eigen::Index j = 0; j < n; ++j)
        damped(j, j) += lambda * std::max(a(j, j), 1e-30);
      step = damped.ldlt().solve(-g);
      const Eigen::VectorXd candidate = x + step;
      const Eigen::VectorXd rc = residuals(candidate);
      const double cc = rc.squaredNorm();
      if (std::isfinite(cc) && cc < cost)
      {
        const double decrease = cost - cc;
        x = candidate;
        r = rc;
        cost = cc;
        lambda = std::max(lambda / 3.0, 1e-12);
        improved = true;
        converged = decrease <= 1e-12 * cost || step.norm() < 1e-10;
        break;
      }
      lambda *= 4.0;
    }
    if (!improved)
      break;
  }
  return {x, cost, it};
}

/// Exact zero-order-hold equivalent of G2(1 + τ1 s)/(1 + σ s + π s²) at z = e^{j2πfT}:
/// G(z) = (1 − z⁻¹) Z{G(s)/s} = r0 + (1 − z⁻¹) Σ_j r_j / (1 − e^{p_j T} z⁻¹), with the partial
/// fractions of G(s)/s: r0 = G2 at s = 0 and r_j at the poles p_j = −1/τ_j (j = 2, 3, distinct,
/// possibly a complex pair), r_j = G2(1 + τ1 p_j)/(p_j π (p_j − p_other)).
Complex currentPerVoltageZoh(const TransferForms& m, double f_hz, double period_s)
{
  Complex tau2 = m.tau2(), tau3 = m.tau3();
  if (std::abs(tau2 - tau3) < 1e-7 * std::abs(tau2))
    tau3 *= 1.0 - 1e-6;  // coincident poles: split by 1e-6 (limit of the partial fractions)
  const Complex p2 = -1.0 / tau2, p3 = -1.0 / tau3;
  const double pi = m.tau_product_s2;
  const Complex r2 = m.g2_a_per_v * (1.0 + m.tau1_s * p2) / (p2 * pi * (p2 - p3));
  const Complex r3 = m.g2_a_per_v * (1.0 + m.tau1_s * p3) / (p3 * pi * (p3 - p2));
  const Complex zinv = std::polar(1.0, -2.0 * kPi * f_hz * period_s);
  return m.g2_a_per_v + (1.0 - zinv) * (r2 / (1.0 - std::exp(p2 * period_s) * zinv) +
                                        r3 / (1.0 - std::exp(p3 * period_s) * zinv));
}

double db(Complex v) { return 20.0 * std::log10(std::abs(v)); }
double deg(double rad) { return rad * 180.0 / kPi; }

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
LmResult fitResponse(const FrequencyResponse& h, const std::vector<std::size_t>& bins, const Model& model,
                     const Eigen::VectorXd& log_initial, double& rms_residual)
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
  LmResult fit = levenbergMarquardt(residuals, log_initial, 200);
  double sum = 0.0;
  for (std::size_t k : bins)
    sum += std::norm(model(fit.x, h.frequency_hz[k]) / h.response[k] - 1.0);
  rms_residual = bins.empty() ? 0.0 : std::sqrt(sum / static_cast<double>(bins.size()));
  return fit;
}

std::string num(double v)
{
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.6g", v);
  return buffer;
}

/// A root as YAML: a number if real, else [re, im] (a complex-conjugate pole pair of i/U).
std::string complexText(Complex v)
{
  if (std::abs(v.imag()) <= 1e-12 * std::abs(v.real()))
    return num(v.real());
  return "[" + num(v.real()) + ", " + num(v.imag()) + "]";
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
  if (!positiveFinite(theta_fit_max_hz) || theta_fit_max_hz > nyquist)
    failSetting("identification.theta_fit_max_hz", "in (0, Nyquist " + num(nyquist) + " Hz]", theta_fit_max_hz);
  if (!positiveFinite(current_fit_max_hz) || current_fit_max_hz > nyquist)
    failSetting("identification.current_fit_max_hz", "in (0, Nyquist " + num(nyquist) + " Hz]", current_fit_max_hz);
  if (!positiveFinite(bode_check_max_hz))
    failSetting("identification.bode_check_max_hz", "> 0", bode_check_max_hz);
}

Complex TransferForms::tau2() const
{
  // Roots of τ² − στ + π = 0; the larger real part (or +imaginary part for a complex pair).
  const Complex disc = std::sqrt(Complex(tau_sum_s * tau_sum_s - 4.0 * tau_product_s2, 0.0));
  return 0.5 * (tau_sum_s + disc);
}

Complex TransferForms::tau3() const
{
  const Complex t2 = tau2();
  return tau_product_s2 / t2;  // the partner root without cancellation
}

TransferForms transferFormsOf(const GalvoPlantParams& p)
{
  const double r = p.resistance_ohm, l = p.inductance_h, kc = p.torque_constant_nm_per_a;
  const double b = p.viscous_nms, j = p.inertia_kgm2;
  TransferForms f;
  f.g1_rad_per_as = kc / b;
  f.tau1_s = j / b;
  f.g2_a_per_v = b / (b * r + kc * kc);
  f.tau_sum_s = f.g2_a_per_v * (l + r * f.tau1_s);
  f.tau_product_s2 = f.g2_a_per_v * l * f.tau1_s;
  return f;
}

PhysicalParams recoverPhysicalParams(const TransferForms& forms)
{
  // THESIS eq. (2.13) as written, in complex arithmetic (see the header).
  const Complex r1 = 1.0 / forms.tau2(), r2 = 1.0 / forms.tau3();
  const double a = forms.tau1_s;
  const Complex c = 1.0 / (forms.g2_a_per_v * a * r1 * r2);
  const Complex b = (a * c * (r1 + r2) - c) / a;
  const Complex d = ((b * a + c) * (b * a + c) - 4.0 * a * c * b - (a * c) * (a * c) * (r1 - r2) * (r1 - r2)) /
                    (4.0 * a * c);
  PhysicalParams out;
  out.inductance_h = c.real();
  out.resistance_ohm = b.real();
  out.torque_constant_nm_per_a = d.real() / forms.g1_rad_per_as;
  out.viscous_nms = out.torque_constant_nm_per_a / forms.g1_rad_per_as;
  out.inertia_kgm2 = a * out.viscous_nms;
  for (double v : {out.inductance_h, out.resistance_ohm, out.torque_constant_nm_per_a, out.viscous_nms,
                   out.inertia_kgm2})
    if (!positiveFinite(v))
    {
      std::ostringstream msg;
      msg << "recoverPhysicalParams: non-positive parameter from G1 " << forms.g1_rad_per_as << ", tau1 "
          << forms.tau1_s << ", G2 " << forms.g2_a_per_v << ", tau2+tau3 " << forms.tau_sum_s << ", tau2*tau3 "
          << forms.tau_product_s2 << " (R " << out.resistance_ohm << ", L " << out.inductance_h << ", Kc "
          << out.torque_constant_nm_per_a << ")";
      throw NumericalError(msg.str());
    }
  return out;
}

Complex thetaPerCurrent(const TransferForms& f, double f_hz)
{
  const Complex s(0.0, 2.0 * kPi * f_hz);
  return f.g1_rad_per_as / (s * (1.0 + f.tau1_s * s));
}

Complex currentPerVoltage(const TransferForms& f, double f_hz)
{
  const Complex s(0.0, 2.0 * kPi * f_hz);
  return f.g2_a_per_v * (1.0 + f.tau1_s * s) / (1.0 + f.tau_sum_s * s + f.tau_product_s2 * s * s);
}

Complex trueThetaPerCurrent(const GalvoPlantParams& p, double f_hz)
{
  const Complex s(0.0, 2.0 * kPi * f_hz);
  const double wr = 2.0 * kPi * p.mode_frequency_hz;
  return p.torque_constant_nm_per_a / (s * (p.inertia_kgm2 * s + p.viscous_nms)) +
         p.mode_gain / (s * s + 2.0 * p.mode_damping * wr * s + wr * wr);
}

Complex trueCurrentPerVoltage(const GalvoPlantParams& p, double f_hz)
{
  const Complex s(0.0, 2.0 * kPi * f_hz);
  const double wr = 2.0 * kPi * p.mode_frequency_hz;
  const Complex speed_per_current = p.torque_constant_nm_per_a / (p.inertia_kgm2 * s + p.viscous_nms) +
                                    p.mode_gain * s / (s * s + 2.0 * p.mode_damping * wr * s + wr * wr);
  return 1.0 / (p.resistance_ohm + p.inductance_h * s + p.torque_constant_nm_per_a * speed_per_current);
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
    settle = std::max(settle, static_cast<std::size_t>(std::ceil(
                                  10.0 / (2.0 * kPi * config.position_loop_hz) / (static_cast<double>(period) * t_s))));
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
    const double volts =
        prbs.next() + kp * (ramp_start + config.ramp_rad_per_s * static_cast<double>(n) * t_s - theta);
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
  const LmResult tfit = fitResponse(hti, tbins, theta_model, x0, result.theta_fit_rms_residual);
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
  const LmResult ifit = fitResponse(hiu, ibins, current_model, y0, result.current_fit_rms_residual);
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
    csv << num(f) << ',' << num(db(t.response[k])) << ',' << num(deg(std::arg(t.response[k]))) << ','
        << num(db(gt)) << ',' << num(deg(std::arg(gt))) << ',' << num(db(tt)) << ',' << num(deg(std::arg(tt)))
        << ',' << num(t.coherence[k]) << ',' << num(db(c.response[k])) << ','
        << num(deg(std::arg(c.response[k]))) << ',' << num(db(gc)) << ',' << num(deg(std::arg(gc))) << ','
        << num(db(tc)) << ',' << num(deg(std::arg(tc))) << ',' << num(c.coherence[k]) << '\n';
  }
  return csv.str();
}

std::string identificationReport(const GalvoPlantParams& truth, const IdentificationConfig& config,
                                 const std::string& out_dir)
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
    << "  friction: " << (config.zero_friction ? "zero  # Tp = Tc = 0 during the experiment" : "as_configured")
    << "\n"
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
    << "  theta_current_band_hz: [" << num(r.theta_per_current.frequency_hz[1]) << ", "
    << num(config.theta_fit_max_hz) << "]\n"
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
    warnings += "\n  - lowest line above the mechanical corner 1/(2 pi tau1): B and Jeq poorly determined; "
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
    const std::string script = resolvePackagePath("scripts/plot_bode.py");
    const std::string command = "/usr/bin/python3 '" + script + "' '" + out_dir + "' 2>&1";
    if (std::system(command.c_str()) != 0)
      std::fprintf(stderr, "scanhead: Bode plots skipped (%s failed; is python3-matplotlib installed?)\n",
                   script.c_str());
  }
  return yaml;
}
}  // namespace scanhead
