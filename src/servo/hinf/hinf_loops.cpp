/// \file hinf_loops.cpp
#include "scanhead/servo/hinf/hinf_loops.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <sstream>
#include <vector>

#include "scanhead/common/errors.hpp"
#include "scanhead/common/text_file.hpp"

namespace scanhead
{
HinfLoops::HinfLoops(const GalvoPlantParams& plant, const CascadeGains& gains, const HinfDesign& design,
                     double controller_period_s, bool voltage_feedforward)
  : cascade_(plant, gains, controller_period_s, voltage_feedforward)
  , k_(design.reduced())
  , k_discrete_(controller_period_s > 0.0 ? triangleHold(design.stable_part, controller_period_s) : StateSpace{})
  , integral_gain_(design.integral_gain)
  , tc_(controller_period_s)
{
}

HinfLoops::Complex HinfLoops::plant(double w) const
{
  const Complex li = cascade_.currentOpenLoop(w);
  return (180.0 / M_PI) * li / (1.0 + li) * cascade_.speedPerCurrent(w) / Complex(0.0, w);
}

HinfLoops::Complex HinfLoops::controller(double w) const
{
  if (tc_ == 0.0)
    return k_.siso(Complex(0.0, w));
  const Complex z = std::exp(Complex(0.0, w * tc_));
  return k_discrete_.siso(z) + integral_gain_ * 0.5 * tc_ * (z + 1.0) / (z - 1.0);
}

HinfLoops::Complex HinfLoops::closedLoop(double w, bool feedforward) const
{
  const Complex s(0.0, w);
  const Complex li = cascade_.currentOpenLoop(w);
  const Complex ti = li / (1.0 + li);
  const Complex h = cascade_.speedPerCurrent(w) / s;  // θ per plant current
  const Complex k = (180.0 / M_PI) * controller(w);
  Complex num = ti * k;
  if (feedforward)
  {
    const CascadeLoops::Feedforward ff = cascade_.feedforward(w);
    num += ti * ff.current + ff.voltage * std::exp(-s * (0.5 * tc_)) * cascade_.currentPerVoltage(w) / (1.0 + li);
  }
  return h * num / (1.0 + ti * k * h);
}

double HinfLoops::lowFrequencyDelay() const
{
  const double w0 = 1e-3;
  return -std::imag(closedLoop(w0, true)) / w0;
}

HinfLoopReport analyseHinfLoops(const GalvoPlantParams& plant, const CascadeGains& gains, const HinfDesign& design,
                                double controller_period_s, bool voltage_feedforward)
{
  const HinfLoops loops(plant, gains, design, controller_period_s, voltage_feedforward);
  HinfLoopReport r;
  r.gamma = design.gamma;
  r.gamma_lower = design.gamma_lower;
  r.moved_pole_rad_s = design.moved_pole;
  r.full_order = design.full.order();
  r.reduced_order = design.stable_part.order() + 1;
  const double w_lo = 0.1;
  const double w_hi = controller_period_s > 0.0 ? std::min(1e7, M_PI / controller_period_s) : 1e7;
  const int per_decade = 400;
  const int n = static_cast<int>(std::ceil(std::log10(w_hi / w_lo) * per_decade));
  std::vector<double> w(n + 1), gain(n + 1), phase(n + 1);
  double peak_s = 0.0, peak_ks = 0.0, peak_sg = 0.0, peak_t = 0.0, prev_arg = 0.0;
  for (int i = 0; i <= n; ++i)
  {
    w[i] = w_lo * std::pow(w_hi / w_lo, static_cast<double>(i) / n);
    const HinfLoops::Complex g = loops.plant(w[i]), k = loops.controller(w[i]), l = k * g;
    const HinfLoops::Complex s = 1.0 / (1.0 + l);
    peak_s = std::max(peak_s, std::abs(s));
    peak_ks = std::max(peak_ks, std::abs(k * s));
    peak_sg = std::max(peak_sg, std::abs(s * g));
    peak_t = std::max(peak_t, std::abs(l * s));
    gain[i] = std::abs(l);
    // Unwrapped: each step's change taken in (−π, π]; the start in (−2π, 0] (two integrators: ≈ −π).
    const double a = std::arg(l);
    phase[i] = i == 0 ? (a > 0.0 ? a - 2.0 * M_PI : a) : phase[i - 1] + std::remainder(a - prev_arg, 2.0 * M_PI);
    prev_arg = a;
  }
  const auto db = [](double x) { return 20.0 * std::log10(x); };
  r.peak_s_db = db(peak_s);
  r.peak_ks_db = db(peak_ks);
  r.peak_sg_db = db(peak_sg);
  r.peak_t_db = db(peak_t);
  // Crossings by linear interpolation in log ω between grid points.
  const auto interpolate = [&](int i, double fa, double fb) {
    const double t = fa / (fa - fb);
    return std::exp(std::log(w[i - 1]) + t * (std::log(w[i]) - std::log(w[i - 1])));
  };
  int crossing = 0;
  for (int i = 1; i <= n && crossing == 0; ++i)
    if (gain[i - 1] >= 1.0 && gain[i] < 1.0)
      crossing = i;
  if (crossing == 0)
    throw NumericalError("analyseHinfLoops: the loop gain never falls below 1");
  r.crossover_rad_s = interpolate(crossing, std::log(gain[crossing - 1]), std::log(gain[crossing]));
  const double t = std::log(r.crossover_rad_s / w[crossing - 1]) / std::log(w[crossing] / w[crossing - 1]);
  r.phase_margin_deg = 180.0 + (phase[crossing - 1] + t * (phase[crossing] - phase[crossing - 1])) * 180.0 / M_PI;
  r.gain_margin_db = INFINITY;
  for (int i = crossing; i <= n; ++i)
    if (phase[i - 1] >= -M_PI && phase[i] < -M_PI)
    {
      r.gain_margin_rad_s = interpolate(i, phase[i - 1] + M_PI, phase[i] + M_PI);
      r.gain_margin_db = -db(std::abs(loops.openLoop(r.gain_margin_rad_s)));
      break;
    }
  r.bandwidth_hz = closedLoopBandwidth([&](double x) { return loops.closedLoop(x, false); });
  r.bandwidth_with_feedforward_hz = closedLoopBandwidth([&](double x) { return loops.closedLoop(x, true); });
  r.low_frequency_delay_s = loops.lowFrequencyDelay();
  return r;
}

double hinfLowFrequencyDelay(const GalvoPlantParams& plant, const CascadeGains& gains, const HinfDesign& design,
                             double controller_period_s, bool voltage_feedforward)
{
  return HinfLoops(plant, gains, design, controller_period_s, voltage_feedforward).lowFrequencyDelay();
}

namespace
{
std::string bodeCsv(const HinfLoops& hinf, const CascadeLoops& pd, const HinfDesign& design, const HinfConfig& weights,
                    double top_hz)
{
  std::ostringstream out;
  out << "frequency_hz,k_full_db,k_full_deg,k_reduced_db,k_reduced_deg,l_hinf_db,l_hinf_deg,l_pd_db,l_pd_deg,"
         "s_hinf_db,ks_hinf_db,sg_hinf_db,t_hinf_db,s_template_db,ks_template_db,sg_template_db,t_template_db,"
         "s_pd_db,t_pd_db\n";
  const StateSpace w1 = weights.w1.stateSpace(), w2 = weights.w2.stateSpace(), w3 = weights.w3.stateSpace();
  const StateSpace reduced = design.reduced();
  const auto db = [](std::complex<double> x) { return 20.0 * std::log10(std::abs(x)); };
  const auto deg = [](std::complex<double> x) { return std::arg(x) * 180.0 / M_PI; };
  out << std::setprecision(7);
  const int n = 600;
  for (int i = 0; i <= n; ++i)
  {
    const double f = std::pow(10.0, std::log10(top_hz) * i / n), w = 2.0 * M_PI * f;
    const std::complex<double> s(0.0, w);
    const auto kf = design.full.siso(s), kr = reduced.siso(s), g = hinf.plant(w), k = hinf.controller(w);
    const auto l = k * g, sens = 1.0 / (1.0 + l);
    const auto lpd = pd.positionOpenLoop(w), tpd = pd.closedLoop(w, false);
    const double gw1 = std::abs(w1.siso(s)), gw2 = std::abs(w2.siso(s)), gw3 = std::abs(w3.siso(s));
    const double g_db = 20.0 * std::log10(design.gamma);
    out << f << ',' << db(kf) << ',' << deg(kf) << ',' << db(kr) << ',' << deg(kr) << ',' << db(l) << ',' << deg(l)
        << ',' << db(lpd) << ',' << deg(lpd) << ',' << db(sens) << ',' << db(k * sens) << ',' << db(sens * g) << ','
        << db(l * sens) << ',' << g_db - 20.0 * std::log10(gw1) << ',' << g_db - 20.0 * std::log10(gw2) << ','
        << g_db - 20.0 * std::log10(gw1 * gw3) << ',' << g_db - 20.0 * std::log10(gw2 * gw3) << ',' << db(1.0 - tpd)
        << ',' << db(tpd) << '\n';
  }
  return out.str();
}
}  // namespace

std::string hinfLoopsReportYaml(const ServoConfig& config, int axis, const std::string& out_dir, const PlotHook& plots)
{
  config.validate();
  if (axis != 0 && axis != 1)
    throw ConfigError("hinfLoopsReportYaml: axis must be 0 (x) or 1 (y) (got " + std::to_string(axis) + ")");
  const AxisLoopConfig& a = axis == 0 ? config.x : config.y;
  const double tc = 1.0 / config.controller_rate_hz;
  const HinfDesign design = designHinfController(a.plant, a.gains, config.hinf);
  const HinfLoopReport r = analyseHinfLoops(a.plant, a.gains, design, tc, config.voltage_feedforward);
  const LoopReport pd = analyseLoops(a.plant, a.gains, tc, config.voltage_feedforward);
  std::ostringstream out;
  out << std::setprecision(6);
  out << "axis: " << (axis == 0 ? "x" : "y") << "\n";
  out << "position_controller: hinf\n";
  out << "controller_rate_hz: " << config.controller_rate_hz << "\n";
  out << "gamma: " << r.gamma << "            # central controller (gamma_tolerance " << config.hinf.gamma_tolerance
      << ")\n";
  out << "gamma_lower: " << r.gamma_lower << "      # largest gamma found infeasible\n";
  out << "full_order: " << r.full_order << "\n";
  out << "reduced_order: " << r.reduced_order << "           # integrator + balanced truncation\n";
  out << "moved_pole_rad_s: " << r.moved_pole_rad_s << "   # smallest pole, moved to the origin\n";
  out << "integral_gain_a_per_deg_s: " << design.integral_gain << "\n";
  out << "crossover_rad_s: " << r.crossover_rad_s << "\n";
  out << "phase_margin_deg: " << r.phase_margin_deg << "\n";
  out << "gain_margin_db: " << r.gain_margin_db << "\n";
  out << "gain_margin_rad_s: " << r.gain_margin_rad_s << "\n";
  out << "bandwidth_hz: " << r.bandwidth_hz << "            # -3 dB of T, feedback only\n";
  out << "bandwidth_with_feedforward_hz: " << r.bandwidth_with_feedforward_hz << "\n";
  out << "peak_s_db: " << r.peak_s_db << "\n";
  out << "peak_ks_db: " << r.peak_ks_db << "           # A/deg\n";
  out << "peak_sg_db: " << r.peak_sg_db << "           # deg/A\n";
  out << "peak_t_db: " << r.peak_t_db << "\n";
  out << "low_frequency_delay_s: " << r.low_frequency_delay_s << "   # ramp lag, feedforward included\n";
  out << "pd:                            # the conventional structure, same axis and rate\n";
  out << "  position_crossover_rad_s: " << pd.position.crossover_rad_s << "\n";
  out << "  position_phase_margin_deg: " << pd.position.phase_margin_deg << "\n";
  out << "  bandwidth_hz: " << pd.bandwidth_hz << "\n";
  if (!out_dir.empty())
  {
    std::error_code ec;
    std::filesystem::create_directories(out_dir, ec);
    if (ec)
      throw InputError(out_dir + ": cannot create (" + ec.message() + ")");
    const HinfLoops loops(a.plant, a.gains, design, tc, config.voltage_feedforward);
    const CascadeLoops pd_loops(a.plant, a.gains, tc, config.voltage_feedforward);
    writeTextFile(out_dir + "/hinf_bode.csv",
                  bodeCsv(loops, pd_loops, design, config.hinf, 0.45 * config.controller_rate_hz));
    if (plots)
      plots(out_dir);
  }
  return out.str();
}
}  // namespace scanhead
