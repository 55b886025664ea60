/// \file contour_error.cpp
/// \brief Brute-force nearest path, same-instant distance and contour error statistics (SPEC §5).
#include "scanhead/metrics/contour_error.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "contour_error_text.hpp"
#include "scanhead/common/errors.hpp"
#include "scanhead/common/segment_distance.hpp"

namespace scanhead
{
namespace
{
constexpr double kPmPerM = 1e12;
constexpr std::uint64_t kPmPerBin = 1000000;  ///< kBinWidth_m in pm
}  // namespace

// ---------------------------------------------------------------------------------------------
// Brute force and same instant

double nearestPathDistanceBruteForce(const PathPoints& path, const Eigen::Vector2d& p)
{
  double best = std::numeric_limits<double>::infinity();
  const std::size_t n = path.size();
  for (std::size_t i = 0; i < n; ++i)
  {
    if (path.joinsNext(i))
      best = std::min(best, pointSegmentDistance(p, path.point(i), path.point(i + 1)));
    else if (i == 0 || !path.joinsNext(i - 1))
      best = std::min(best, (path.point(i) - p).norm());  // isolated point
  }
  return best;
}

double sameInstantDistance(const PathPoints& path, std::size_t j, const Eigen::Vector2d& p)
{
  if (j >= path.size())
  {
    throw InputError("contour error: same-instant sample " + std::to_string(j) + " is beyond the actual path (" +
                     std::to_string(path.size()) + " points)");
  }
  if (!p.allFinite())
    throw InputError("contour error: commanded point " + pointText(p) + " m is not finite");
  const Eigen::Vector2d pj = path.point(j);
  const bool before = j > 0 && path.joinsNext(j - 1);
  const bool after = path.joinsNext(j);
  if (!before && !after)
    return (pj - p).norm();
  double best2 = std::numeric_limits<double>::infinity();  // squared: one root for both segments
  if (before)
    best2 = pointSegmentDistance2(p, path.point(j - 1), pj);
  if (after)
    best2 = std::min(best2, pointSegmentDistance2(p, pj, path.point(j + 1)));
  return std::sqrt(best2);
}

// ---------------------------------------------------------------------------------------------
// ContourErrorStats

void ContourErrorStats::add(double error_m)
{
  if (!(error_m >= 0.0) || error_m > kMaxError_m)
  {
    throw NumericalError("contour error: error " + fullPrecisionText(error_m) + " m is NaN, negative or above " +
                         fullPrecisionText(kMaxError_m) + " m");
  }
  const auto q = static_cast<std::uint64_t>(std::llround(error_m * kPmPerM));
  ++count_;
  sum_pm_low_ += q;
  if (sum_pm_low_ < q)
    ++sum_pm_high_;
  max_m_ = std::max(max_m_, error_m);
  ++bins_[std::min<std::uint64_t>(q / kPmPerBin, kBins)];
}

void ContourErrorStats::merge(const ContourErrorStats& other)
{
  count_ += other.count_;
  sum_pm_low_ += other.sum_pm_low_;
  sum_pm_high_ += other.sum_pm_high_ + (sum_pm_low_ < other.sum_pm_low_ ? 1 : 0);
  max_m_ = std::max(max_m_, other.max_m_);
  for (std::size_t b = 0; b <= kBins; ++b)
    bins_[b] += other.bins_[b];
}

double ContourErrorStats::mean() const
{
  if (count_ == 0)
    return std::numeric_limits<double>::quiet_NaN();
  const double sum_pm = static_cast<double>(sum_pm_high_) * 18446744073709551616.0 + static_cast<double>(sum_pm_low_);
  return sum_pm / static_cast<double>(count_) / kPmPerM;
}

double ContourErrorStats::max() const
{
  return count_ == 0 ? std::numeric_limits<double>::quiet_NaN() : max_m_;
}

std::uint64_t ContourErrorStats::countUnder(double limit_m) const
{
  const double bins = limit_m / kBinWidth_m;
  const double whole = std::round(bins);
  if (!(std::abs(bins - whole) <= 1e-9) || whole < 0.0 || whole > static_cast<double>(kBins))
  {
    throw InputError("contour error: limit " + fullPrecisionText(limit_m) + " m is not a multiple of the " +
                     fullPrecisionText(kBinWidth_m) + " m bin in [0, " + fullPrecisionText(kBins * kBinWidth_m) +
                     "] m");
  }
  std::uint64_t n = 0;
  for (std::size_t b = 0; b < static_cast<std::size_t>(whole); ++b)
    n += bins_[b];
  return n;
}

double ContourErrorStats::shareUnder(double limit_m) const
{
  const std::uint64_t n = countUnder(limit_m);
  return count_ == 0 ? std::numeric_limits<double>::quiet_NaN() : static_cast<double>(n) / static_cast<double>(count_);
}

std::uint64_t ContourErrorStats::binCount(std::size_t bin) const
{
  if (bin > kBins)
    throw InputError("contour error: histogram bin " + std::to_string(bin) + " is beyond the overflow bin " +
                     std::to_string(kBins));
  return bins_[bin];
}

double ContourErrorStats::quantileUpperBound(double fraction) const
{
  if (!(fraction >= 0.0 && fraction <= 1.0))
    throw InputError("contour error: quantile fraction " + fullPrecisionText(fraction) + " is outside [0, 1]");
  if (count_ == 0)
    return std::numeric_limits<double>::quiet_NaN();
  const auto rank =
      std::max<std::uint64_t>(1, static_cast<std::uint64_t>(std::ceil(fraction * static_cast<double>(count_))));
  std::uint64_t seen = 0;
  for (std::size_t b = 0; b < kBins; ++b)
  {
    seen += bins_[b];
    if (seen >= rank)
      return std::min(static_cast<double>(b + 1) * kBinWidth_m, max_m_);
  }
  return max_m_;
}

bool ContourErrorStats::operator==(const ContourErrorStats& other) const
{
  return count_ == other.count_ && sum_pm_low_ == other.sum_pm_low_ && sum_pm_high_ == other.sum_pm_high_ &&
         max_m_ == other.max_m_ && bins_ == other.bins_;
}
}  // namespace scanhead
