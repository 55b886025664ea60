/// \file stroke_merger.cpp
/// \brief Merging of the samples' segments into straight constant-velocity strokes.
#include "scanhead/energy/stroke_merger.hpp"

#include <algorithm>
#include <cmath>

namespace scanhead
{
StrokeMerger::StrokeMerger(double tolerance_m, double pixel_m)
  : tolerance_m_(tolerance_m)
  , max_length_m_(kMaxStrokePixels * pixel_m)
{
}

void StrokeMerger::reset()
{
  stroke_ = Stroke();
}

bool StrokeMerger::continues(const Eigen::Vector2d& a, const Eigen::Vector2d& b, double power_w, double period_s,
                             const SpotFootprint& fp, Eigen::Vector2d& step) const
{
  const Stroke& s = stroke_;
  if (power_w != s.power_w || period_s != s.period_s || s.samples >= kMaxStrokeSamples)
    return false;
  const SpotFootprint& q = s.footprint;
  const double dq = std::max(std::abs(fp.qxx - q.qxx), std::abs(fp.qyy - q.qyy)) + std::abs(fp.qxy - q.qxy);
  if (dq * q.major_radius_m * q.major_radius_m / (2.0 * M_E) > kFootprintTolerance)
    return false;
  const double n = static_cast<double>(s.samples);
  if (s.samples < kFitSamples)
  {
    // The chord x_0 → b, then every sample of the stroke checked against it.
    step = (b - s.start) / (n + 1.0);
    if ((n + 1.0) * step.norm() > max_length_m_ || (a - (s.start + n * step)).norm() > tolerance_m_)
      return false;
    for (std::uint64_t k = 1; k <= s.samples; ++k)
      if ((points_[k - 1] - (s.start + static_cast<double>(k) * step)).norm() > tolerance_m_)
        return false;
    return true;
  }
  step = s.step;
  if ((n + 1.0) * s.step.norm() > max_length_m_)
    return false;
  return (a - (s.start + n * s.step)).norm() <= tolerance_m_ &&
         (b - (s.start + (n + 1.0) * s.step)).norm() <= tolerance_m_;
}

bool StrokeMerger::add(const Eigen::Vector2d& a, const Eigen::Vector2d& b, double power_w, double period_s,
                       const SpotFootprint& fp, Stroke& done)
{
  Eigen::Vector2d step;
  if (stroke_.samples > 0 && continues(a, b, power_w, period_s, fp, step))
  {
    stroke_.step = step;
    if (stroke_.samples < kFitSamples)
      points_[stroke_.samples] = b;
    ++stroke_.samples;
    return false;
  }
  const bool flushed = flush(done);
  stroke_.start = a;
  stroke_.step = b - a;
  stroke_.samples = 1;
  stroke_.power_w = power_w;
  stroke_.period_s = period_s;
  stroke_.footprint = fp;
  points_[0] = b;
  return flushed;
}

bool StrokeMerger::flush(Stroke& done)
{
  if (stroke_.samples == 0)
    return false;
  done = stroke_;
  stroke_.samples = 0;
  return true;
}
}  // namespace scanhead
