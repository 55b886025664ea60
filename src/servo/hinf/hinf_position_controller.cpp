/// \file hinf_position_controller.cpp
#include "scanhead/servo/hinf/hinf_position_controller.hpp"

#include "scanhead/common/errors.hpp"

namespace scanhead
{
HinfPositionController::HinfPositionController(const HinfDesign& design, double period_s)
{
  if (design.stable_part.order() > kMaxOrder)
    throw NumericalError("H-infinity controller: more than 16 states (servo.hinf.reduced_order)");
  const StateSpace k = triangleHold(design.stable_part, period_s);
  a_ = k.a;
  b_ = k.b;
  c_ = k.c.transpose();
  d_ = k.d(0, 0);
  half_ki_t_ = 0.5 * design.integral_gain * period_s;
  reset();
}

void HinfPositionController::reset()
{
  x_ = Vector::Zero(a_.rows());
  integral_ = integral_new_ = error_prev_ = error_ = 0.0;
}

double HinfPositionController::update(double error_deg)
{
  error_ = error_deg;
  integral_new_ = integral_ + half_ki_t_ * (error_deg + error_prev_);
  return integral_new_ + c_.dot(x_) + d_ * error_deg;
}

void HinfPositionController::commit(bool hold_integral)
{
  x_ = a_ * x_ + b_ * error_;
  error_prev_ = error_;
  if (!hold_integral)
    integral_ = integral_new_;
}
}  // namespace scanhead
