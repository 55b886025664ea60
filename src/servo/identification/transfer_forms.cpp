/// \file transfer_forms.cpp
#include "scanhead/servo/identification/transfer_forms.hpp"

#include <cmath>
#include <sstream>

#include "scanhead/common/errors.hpp"

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
}  // namespace

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
  const Complex d =
      ((b * a + c) * (b * a + c) - 4.0 * a * c * b - (a * c) * (a * c) * (r1 - r2) * (r1 - r2)) / (4.0 * a * c);
  PhysicalParams out;
  out.inductance_h = c.real();
  out.resistance_ohm = b.real();
  out.torque_constant_nm_per_a = d.real() / forms.g1_rad_per_as;
  out.viscous_nms = out.torque_constant_nm_per_a / forms.g1_rad_per_as;
  out.inertia_kgm2 = a * out.viscous_nms;
  for (double v :
       {out.inductance_h, out.resistance_ohm, out.torque_constant_nm_per_a, out.viscous_nms, out.inertia_kgm2})
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
  return m.g2_a_per_v +
         (1.0 - zinv) * (r2 / (1.0 - std::exp(p2 * period_s) * zinv) + r3 / (1.0 - std::exp(p3 * period_s) * zinv));
}
}  // namespace scanhead
