/// \file loop_analysis.cpp
#include "scanhead/servo/loop_analysis.hpp"

#include <cmath>
#include <iomanip>
#include <sstream>

#include "scanhead/common/errors.hpp"

namespace scanhead
{
namespace
{
constexpr double kPi = 3.14159265358979323846;
using Complex = std::complex<double>;

Complex pi(double k, double ti, Complex s)
{
  return k * (1.0 + 1.0 / (ti * s));
}

Complex pd(double k, double td, Complex s)
{
  return k * (1.0 + td * s / (1.0 + td / 100.0 * s));
}

/// \brief First w on a log grid where pred(w) turns true after being false, refined by bisection.
template <class Pred>
double firstCrossing(const Pred& pred, double w_lo, double w_hi, const char* what)
{
  const int per_decade = 200;
  const int n = static_cast<int>(std::ceil(std::log10(w_hi / w_lo) * per_decade));
  double prev = w_lo;
  if (pred(prev))
  {
    throw NumericalError(std::string(what) + ": condition already met at the lowest frequency");
  }
  for (int k = 1; k <= n; ++k)
  {
    const double w = w_lo * std::pow(10.0, static_cast<double>(k) / per_decade);
    if (pred(w))
    {
      double lo = prev, hi = w;
      for (int it = 0; it < 100; ++it)
      {
        const double mid = std::sqrt(lo * hi);
        (pred(mid) ? hi : lo) = mid;
      }
      return std::sqrt(lo * hi);
    }
    prev = w;
  }
  throw NumericalError(std::string(what) + ": no crossing below " + std::to_string(w_hi) + " rad/s");
}

/// \brief Phase [deg] of f at w, unwrapped continuously from w_lo along a log grid.
double unwrappedPhaseDeg(const std::function<Complex(double)>& f, double w_lo, double w)
{
  const int per_decade = 400;
  const int n = std::max(1, static_cast<int>(std::ceil(std::log10(w / w_lo) * per_decade)));
  double phase = std::arg(f(w_lo));
  double prev = phase;
  for (int k = 1; k <= n; ++k)
  {
    const double wk = w_lo * std::pow(w / w_lo, static_cast<double>(k) / n);
    const double a = std::arg(f(wk));
    double d = a - prev;
    while (d > kPi)
      d -= 2.0 * kPi;
    while (d < -kPi)
      d += 2.0 * kPi;
    phase += d;
    prev = a;
  }
  return phase * 180.0 / kPi;
}

/// \brief The phase the controller may take at the crossover for \p margin_deg, given the loop's other phase.
double allowedControllerPhase(double other_phase_rad, double margin_deg)
{
  return margin_deg * kPi / 180.0 - kPi - other_phase_rad;
}

/// \brief Angle of the PI's zero that leaves \p margin_deg at wc given the loop's other phase.
double integralTime(double wc, double other_phase_rad, double margin_deg)
{
  const double need = allowedControllerPhase(other_phase_rad, margin_deg);  // arg REG required (≤ 0)
  if (need >= 0.0)
  {
    return 1e9;  // the plant alone has more margin: integral action negligible at wc (Ti = 1e9 s)
  }
  if (need <= -kPi / 2.0)
  {
    throw NumericalError("synthesiseGains: a PI cannot reach the phase margin at the target crossover");
  }
  return 1.0 / (wc * std::tan(-need));
}

constexpr double kLowW = 1e-2;  ///< start of the phase unwrapping [rad/s]
}  // namespace

CascadeLoops::CascadeLoops(const GalvoPlantParams& plant, const CascadeGains& gains, double controller_period_s,
                           bool voltage_feedforward)
  : p_(plant)
  , g_(gains)
  , tc_(controller_period_s)
  , voltage_ff_(voltage_feedforward)
{
}

CascadeLoops::Complex CascadeLoops::speedPerCurrent(double w) const
{
  const Complex s(0.0, w);
  const double wr = 2.0 * kPi * p_.mode_frequency_hz;
  return p_.torque_constant_nm_per_a / (p_.inertia_kgm2 * s + p_.viscous_nms) +
         p_.mode_gain * s / (s * s + 2.0 * p_.mode_damping * wr * s + wr * wr);
}

CascadeLoops::Complex CascadeLoops::currentPerVoltage(double w) const
{
  const Complex s(0.0, w);
  return 1.0 / (p_.inductance_h * s + p_.resistance_ohm + p_.torque_constant_nm_per_a * speedPerCurrent(w));
}

CascadeLoops::Complex CascadeLoops::currentOpenLoop(double w) const
{
  const Complex s(0.0, w);
  return pi(g_.kii, g_.tii_s, s) * std::exp(-s * (0.5 * tc_)) * currentPerVoltage(w);
}

CascadeLoops::Complex CascadeLoops::speedOpenLoop(double w) const
{
  const Complex s(0.0, w);
  const Complex li = currentOpenLoop(w);
  return pi(g_.kiw, g_.tiw_s, s) * li / (1.0 + li) * speedPerCurrent(w);
}

CascadeLoops::Complex CascadeLoops::positionOpenLoop(double w) const
{
  const Complex s(0.0, w);
  const Complex lw = speedOpenLoop(w);
  return pd(g_.ktheta, g_.tdtheta_s, s) * lw / (1.0 + lw) / s;
}

CascadeLoops::Complex CascadeLoops::closedLoop(double w, bool feedforward) const
{
  const Complex s(0.0, w);
  const Complex li = currentOpenLoop(w);
  const Complex ti = li / (1.0 + li);
  const Complex lw = pi(g_.kiw, g_.tiw_s, s) * ti * speedPerCurrent(w);
  const Complex tw = lw / (1.0 + lw);
  const Complex reg = pd(g_.ktheta, g_.tdtheta_s, s);
  if (!feedforward)
  {
    const Complex lt = reg * tw / s;
    return lt / (1.0 + lt);
  }
  const Feedforward ff = this->feedforward(w);
  const Complex h_w_ei = ti * speedPerCurrent(w) / (1.0 + lw);
  Complex num = (reg + ff.speed) * tw + ff.current * h_w_ei;
  if (voltage_ff_)
  {
    // FF_U enters like the current PI's output (delay Tc/2).
    const Complex s_u = std::exp(-s * (0.5 * tc_)) * currentPerVoltage(w) / (1.0 + li);
    num += ff.voltage * s_u * speedPerCurrent(w) / (1.0 + lw);
  }
  return num / (s + reg * tw);
}

CascadeLoops::Feedforward CascadeLoops::feedforward(double w) const
{
  const Complex s(0.0, w);
  // 1/(1 + τf s) as the controller realises it: step-invariant pole a = e^{−Tc/τf} on the current
  // input, (1 − a)/(1 − a e^{−sTc}) (the continuous form when Tc = 0).
  Complex f = 1.0 / (1.0 + g_.tauf_s * s);
  if (tc_ > 0.0)
  {
    const double a = g_.tauf_s > 0.0 ? std::exp(-tc_ / g_.tauf_s) : 0.0;
    f = (1.0 - a) / (1.0 - a * std::exp(-s * tc_));
  }
  Feedforward ff;
  ff.speed = g_.k1 * s * f;
  ff.current = g_.k2 * (p_.inertia_kgm2 / p_.torque_constant_nm_per_a) * s * s * f * f;
  ff.voltage = 0.0;
  if (voltage_ff_)
  {
    // FF_U = R FF_i + L d(FF_i)/dt + Ke FF_ω, the derivative as the controller takes it: the backward
    // difference (1 − e^{−sTc})/Tc (s when Tc = 0).
    const Complex d_ff_i = tc_ > 0.0 ? ff.current * (1.0 - std::exp(-s * tc_)) / tc_ : ff.current * s;
    ff.voltage = p_.resistance_ohm * ff.current + p_.inductance_h * d_ff_i + p_.torque_constant_nm_per_a * ff.speed;
  }
  return ff;
}

LoopMargin loopMargin(const std::function<Complex(double)>& open_loop)
{
  LoopMargin m;
  m.crossover_rad_s = firstCrossing([&](double w) { return std::abs(open_loop(w)) < 1.0; }, 1.0, 1e7, "loopMargin");
  m.phase_margin_deg = 180.0 + unwrappedPhaseDeg(open_loop, kLowW, m.crossover_rad_s);
  return m;
}

double closedLoopBandwidth(const std::function<Complex(double)>& closed_loop)
{
  const double w = firstCrossing([&](double x) { return std::abs(closed_loop(x)) < std::sqrt(0.5); }, 1.0, 1e7,
                                 "closedLoopBandwidth");
  return w / (2.0 * kPi);
}

double closedLoopBandwidth(const CascadeLoops& loops, bool feedforward)
{
  return closedLoopBandwidth([&](double w) { return loops.closedLoop(w, feedforward); });
}

double lowFrequencyDelay(const GalvoPlantParams& plant, const CascadeGains& gains, double controller_period_s,
                         bool voltage_feedforward)
{
  const double w0 = 1e-3;
  return -std::imag(CascadeLoops(plant, gains, controller_period_s, voltage_feedforward).closedLoop(w0, true)) / w0;
}

LoopReport analyseLoops(const GalvoPlantParams& plant, const CascadeGains& gains, double controller_period_s,
                        bool voltage_feedforward)
{
  const CascadeLoops loops(plant, gains, controller_period_s, voltage_feedforward);
  LoopReport r;
  r.current = loopMargin([&](double w) { return loops.currentOpenLoop(w); });
  r.speed = loopMargin([&](double w) { return loops.speedOpenLoop(w); });
  r.position = loopMargin([&](double w) { return loops.positionOpenLoop(w); });
  r.bandwidth_hz = closedLoopBandwidth(loops, false);
  r.bandwidth_with_feedforward_hz = closedLoopBandwidth(loops, true);
  double peak = 0.0;
  for (int k = 0; k <= 2000; ++k)
  {
    const double w = 2.0 * kPi * std::pow(10.0, 4.7 * k / 2000.0);
    peak = std::max(peak, std::abs(loops.closedLoop(w, true)));
  }
  r.peak_with_feedforward_db = 20.0 * std::log10(peak);
  r.low_frequency_delay_s = lowFrequencyDelay(plant, gains, controller_period_s, voltage_feedforward);
  // The mode: the peak of |H_ω/i − Kc/(Jeq s + B)| (= Kr s/(s² + 2ξ ωres s + ωres²), peak at ωres).
  double best = 0.0;
  const double f0 = plant.mode_frequency_hz;
  for (int k = -2000; k <= 2000; ++k)
  {
    const double f = f0 * std::pow(10.0, k / 4000.0);  // ±0.5 decade, 0.06 % steps
    const Complex s(0.0, 2.0 * kPi * f);
    const double mag = std::abs(loops.speedPerCurrent(2.0 * kPi * f) -
                                plant.torque_constant_nm_per_a / (plant.inertia_kgm2 * s + plant.viscous_nms));
    if (mag > best)
    {
      best = mag;
      r.mode_frequency_hz = f;
    }
  }
  r.controller_rate_hz = controller_period_s > 0.0 ? 1.0 / controller_period_s : 0.0;
  return r;
}

LoopTargets LoopTargets::scaled(double k) const
{
  LoopTargets t = *this;
  t.current_crossover_rad_s *= k;
  t.speed_crossover_rad_s *= k;
  t.position_crossover_rad_s *= k;
  t.speed_integral_time_s /= k;  // a time of the loop's shape: ∝ 1/ωc
  return t;
}

CascadeGains synthesiseGains(const GalvoPlantParams& plant, const LoopTargets& targets, double controller_period_s,
                             const CascadeGains& base)
{
  CascadeGains g = base;
  // Current loop on H_i/U with the hold delay.
  {
    const CascadeLoops l(plant, g, controller_period_s);
    const double wc = targets.current_crossover_rad_s;
    const Complex s(0.0, wc);
    const Complex h = std::exp(-s * (0.5 * controller_period_s)) * l.currentPerVoltage(wc);
    g.tii_s = integralTime(wc, std::arg(h), targets.current_margin_deg);
    g.kii = 1.0 / std::abs(pi(1.0, g.tii_s, s) * h);
  }
  // Speed loop on T_i·H_ω/i.
  {
    const CascadeLoops l(plant, g, controller_period_s);
    const double wc = targets.speed_crossover_rad_s;
    const Complex s(0.0, wc);
    const Complex li = l.currentOpenLoop(wc);
    const Complex h = li / (1.0 + li) * l.speedPerCurrent(wc);
    if (targets.speed_integral_time_s > 0.0)
    {
      g.tiw_s = targets.speed_integral_time_s;
      // The PI's phase at wc, −atan(1/(wc Ti)), must leave at least the margin.
      if (-std::atan(1.0 / (wc * g.tiw_s)) < allowedControllerPhase(std::arg(h), targets.speed_margin_deg))
      {
        throw NumericalError("synthesiseGains: the given speed integral time leaves less than the speed phase margin");
      }
    }
    else
    {
      g.tiw_s = integralTime(wc, std::arg(h), targets.speed_margin_deg);
    }
    g.kiw = 1.0 / std::abs(pi(1.0, g.tiw_s, s) * h);
  }
  // Position loop on T_ω/s, PD on the decreasing branch of its lead.
  {
    const CascadeLoops l(plant, g, controller_period_s);
    const double wc = targets.position_crossover_rad_s;
    const Complex s(0.0, wc);
    const Complex lw = l.speedOpenLoop(wc);
    const Complex h = lw / (1.0 + lw) / s;
    const double need = allowedControllerPhase(std::arg(h), targets.position_margin_deg);
    double lo = 1.0 / (0.1005 * wc);  // lead maximum (zero 1.01 Td, pole Td/100: ω = 1/(Td √(1.01·0.01)))
    double hi = 1e3;
    const auto lead = [&](double td) { return std::arg(pd(1.0, td, s)); };
    if (!(lead(lo) >= need && lead(hi) <= need))
    {
      throw NumericalError("synthesiseGains: the PD cannot reach the position phase margin");
    }
    for (int it = 0; it < 200; ++it)
    {
      const double mid = std::sqrt(lo * hi);
      (lead(mid) > need ? lo : hi) = mid;
    }
    g.tdtheta_s = std::sqrt(lo * hi);
    g.ktheta = 1.0 / std::abs(pd(1.0, g.tdtheta_s, s) * h);
  }
  return g;
}

std::string loopsReportYaml(const ServoConfig& config, int axis)
{
  config.validate();
  if (axis != 0 && axis != 1)
  {
    throw ConfigError("loopsReportYaml: axis must be 0 (x) or 1 (y) (got " + std::to_string(axis) + ")");
  }
  const AxisLoopConfig& a = axis == 0 ? config.x : config.y;
  const LoopReport r = analyseLoops(a.plant, a.gains, 1.0 / config.controller_rate_hz, config.voltage_feedforward);
  std::ostringstream out;
  out << std::setprecision(6);
  out << "axis: " << (axis == 0 ? "x" : "y") << "\n";
  out << "controller_rate_hz: " << r.controller_rate_hz << "\n";
  out << "bandwidth_hz: " << r.bandwidth_hz
      << "            # -3 dB of theta/theta_ref, feedback only (THESIS Fig. 2.40)\n";
  out << "voltage_feedforward: " << (config.voltage_feedforward ? "true" : "false") << "\n";
  out << "bandwidth_with_feedforward_hz: " << r.bandwidth_with_feedforward_hz << "\n";
  out << "peak_with_feedforward_db: " << r.peak_with_feedforward_db << "\n";
  out << "position_crossover_rad_s: " << r.position.crossover_rad_s << "\n";
  out << "position_phase_margin_deg: " << r.position.phase_margin_deg << "\n";
  out << "speed_crossover_rad_s: " << r.speed.crossover_rad_s << "\n";
  out << "speed_phase_margin_deg: " << r.speed.phase_margin_deg << "\n";
  out << "current_crossover_rad_s: " << r.current.crossover_rad_s << "\n";
  out << "current_phase_margin_deg: " << r.current.phase_margin_deg << "\n";
  out << "low_frequency_delay_s: " << r.low_frequency_delay_s << "   # ramp lag, feedforward included\n";
  out << "mode_frequency_hz: " << r.mode_frequency_hz << "\n";
  return out.str();
}
}  // namespace scanhead
