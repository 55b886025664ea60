/// \file prbs.cpp
#include "scanhead/servo/identification/prbs.hpp"

#include <cmath>
#include <sstream>

#include "scanhead/common/config_check.hpp"
#include "scanhead/common/errors.hpp"

namespace scanhead
{
namespace
{
constexpr int kMinOrder = 2;
constexpr int kMaxOrder = 24;

/// Taps (1-based register stages) of maximal-length LFSRs, Xilinx XAPP052 Table 3; index = order.
/// Every entry is checked by test_prbs (full period for all orders 2..24).
const int kTaps[kMaxOrder + 1][4] = {{0, 0, 0, 0},   {0, 0, 0, 0},    {2, 1, 0, 0},   {3, 2, 0, 0},   {4, 3, 0, 0},
                                     {5, 3, 0, 0},   {6, 5, 0, 0},    {7, 6, 0, 0},   {8, 6, 5, 4},   {9, 5, 0, 0},
                                     {10, 7, 0, 0},  {11, 9, 0, 0},   {12, 6, 4, 1},  {13, 4, 3, 1},  {14, 5, 3, 1},
                                     {15, 14, 0, 0}, {16, 15, 13, 4}, {17, 14, 0, 0}, {18, 11, 0, 0}, {19, 6, 2, 1},
                                     {20, 17, 0, 0}, {21, 19, 0, 0},  {22, 21, 0, 0}, {23, 18, 0, 0}, {24, 23, 22, 17}};

}  // namespace

void PrbsConfig::validate(const std::string& prefix) const
{
  if (order < kMinOrder || order > kMaxOrder)
    failSetting(prefix + ".order", "in [2, 24]", order);
  if (clock_divider < 1)
    failSetting(prefix + ".clock_divider", ">= 1", clock_divider);
  if (!(amplitude > 0.0) || !std::isfinite(amplitude))
    failSetting(prefix + ".amplitude", "> 0 and finite", amplitude);
}

Prbs::Prbs(const PrbsConfig& config)
  : config_(config)
{
  config_.validate("prbs");
  period_bits_ = (std::size_t{1} << config_.order) - 1;
  for (int tap : kTaps[config_.order])
    if (tap > 0)
      feedback_mask_ |= std::uint32_t{1} << (tap - 1);
  reset();
}

void Prbs::reset()
{
  state_ = static_cast<std::uint32_t>(period_bits_);  // all ones (any non-zero state works)
  hold_ = 0;
}

double Prbs::next()
{
  if (hold_ == 0)
  {
    // Output the last stage, then shift in the XOR (parity) of the tapped stages.
    const std::uint32_t out = (state_ >> (config_.order - 1)) & 1u;
    std::uint32_t taps = state_ & feedback_mask_;
    std::uint32_t parity = 0;
    while (taps != 0)
    {
      parity ^= 1u;
      taps &= taps - 1;
    }
    state_ = ((state_ << 1) | parity) & static_cast<std::uint32_t>(period_bits_);
    level_ = out != 0 ? config_.amplitude : -config_.amplitude;
    hold_ = config_.clock_divider;
  }
  --hold_;
  return level_;
}

std::vector<double> Prbs::take(std::size_t count)
{
  std::vector<double> out(count);
  for (double& v : out)
    v = next();
  return out;
}
}  // namespace scanhead
