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
                             const SpotFootprint& fp) const
{
  const Stroke& s = stroke_;
  if (power_w != s.power_w || period_s != s.period_s || s.samples >= kMaxStrokeSamples)
    return false;
  const double n = static_cast<double>(s.samples);
  if ((n + 1.0) * s.step.norm() > max_length_m_)
    return false;
  if ((a - (s.start + n * s.step)).norm() > tolerance_m_ || (b - (s.start + (n + 1.0) * s.step)).norm() > tolerance_m_)
    return false;
  const SpotFootprint& q = s.footprint;
  const double dq = std::max(std::abs(fp.qxx - q.qxx), std::abs(fp.qyy - q.qyy)) + std::abs(fp.qxy - q.qxy);
  return dq * q.major_radius_m * q.major_radius_m / (2.0 * M_E) <= kFootprintTolerance;
}

bool StrokeMerger::add(const Eigen::Vector2d& a, const Eigen::Vector2d& b, double power_w, double period_s,
                       const SpotFootprint& fp, Stroke& done)
{
  if (stroke_.samples > 0 && continues(a, b, power_w, period_s, fp))
  {
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
