/// \file histogram.cpp
#include "scanhead/common/histogram.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "scanhead/common/errors.hpp"
#include "scanhead/common/number_text.hpp"

namespace scanhead
{
namespace
{
constexpr int kMaxBins = 1 << 24;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

}  // namespace

Histogram::Histogram(double lo, double hi, int bins)
  : lo_(lo)
  , hi_(hi)
  , span_(hi - lo)
  , min_(kNaN)
  , max_(kNaN)
{
  if (!std::isfinite(lo) || !std::isfinite(hi) || !(lo < hi) || !std::isfinite(span_))
  {
    throw ConfigError("histogram: the range must be finite with lo < hi (got lo " + fullPrecisionText(lo) + ", hi " +
                      fullPrecisionText(hi) + ")");
  }
  if (bins < 1 || bins > kMaxBins)
  {
    throw ConfigError("histogram: bins must be in 1 .. " + std::to_string(kMaxBins) + " (got " + std::to_string(bins) +
                      ")");
  }
  counts_.assign(static_cast<std::size_t>(bins), 0);
  edges_.resize(static_cast<std::size_t>(bins) + 1);
  for (int i = 0; i < bins; ++i)
    edges_[static_cast<std::size_t>(i)] =
        lo_ + span_ * i / bins;  // monotonic in i: each operation rounds monotonically
  edges_.back() = hi_;
  scale_ = bins / span_;
  for (int i = 0; i < bins; ++i)
  {
    if (!(binEdge(i + 1) > binEdge(i)))
    {
      throw ConfigError("histogram: " + std::to_string(bins) + " bins over [" + fullPrecisionText(lo) + ", " +
                        fullPrecisionText(hi) + "] have coinciding edges in double precision");
    }
  }
}

double Histogram::binEdge(int i) const
{
  const int n = bins();
  if (i < 0 || i > n)
    throw std::out_of_range("histogram: edge " + std::to_string(i) + " of " + std::to_string(n) + " bins");
  return edges_[static_cast<std::size_t>(i)];
}

std::uint64_t Histogram::binCount(int i) const
{
  if (i < 0 || i >= bins())
    throw std::out_of_range("histogram: bin " + std::to_string(i) + " of " + std::to_string(bins()));
  return counts_[static_cast<std::size_t>(i)];
}

int Histogram::binOf(double x) const
{
  // A guess, then the edges decide (the guess may round across one): any guess gives the same bin.
  const int n = bins();
  const double guess = (x - lo_) * scale_;  // truncated, not floored: below 0 the clamp gives 0 either way
  int i = guess > 0.0 ? (guess < n - 1 ? static_cast<int>(guess) : n - 1) : 0;
  const double* edge = edges_.data();
  while (i > 0 && x < edge[i])
    --i;
  while (i + 1 < n && x >= edge[i + 1])
    ++i;
  return i;
}

void Histogram::add(double x)
{
  if (!std::isfinite(x))
  {
    ++non_finite_;
    return;
  }
  if (x < lo_)
    ++underflow_;
  else if (x > hi_)
    ++overflow_;
  else
  {
    ++counts_[static_cast<std::size_t>(binOf(x))];
    ++in_range_;
  }
  if (count() == 1)
    min_ = max_ = x;
  else
  {
    min_ = std::min(min_, x);
    max_ = std::max(max_, x);
  }
  // Neumaier: the rounding error of each addition is kept apart.
  const double t = sum_ + x;
  sum_compensation_ += std::fabs(sum_) >= std::fabs(x) ? (sum_ - t) + x : (x - t) + sum_;
  sum_ = t;
}

void Histogram::merge(const Histogram& other)
{
  if (other.lo_ != lo_ || other.hi_ != hi_ || other.bins() != bins())
  {
    throw std::invalid_argument("histogram: cannot merge [" + fullPrecisionText(other.lo_) + ", " +
                                fullPrecisionText(other.hi_) + "] / " + std::to_string(other.bins()) + " bins into [" +
                                fullPrecisionText(lo_) + ", " + fullPrecisionText(hi_) + "] / " +
                                std::to_string(bins()) + " bins");
  }
  if (other.count() > 0)
  {
    min_ = count() > 0 ? std::min(min_, other.min_) : other.min_;
    max_ = count() > 0 ? std::max(max_, other.max_) : other.max_;
  }
  for (std::size_t i = 0; i < counts_.size(); ++i)
    counts_[i] += other.counts_[i];
  in_range_ += other.in_range_;
  underflow_ += other.underflow_;
  overflow_ += other.overflow_;
  non_finite_ += other.non_finite_;
  const double x = other.sum_;
  const double t = sum_ + x;
  sum_compensation_ += (std::fabs(sum_) >= std::fabs(x) ? (sum_ - t) + x : (x - t) + sum_) + other.sum_compensation_;
  sum_ = t;
}

void Histogram::reset()
{
  std::fill(counts_.begin(), counts_.end(), 0);
  in_range_ = underflow_ = overflow_ = non_finite_ = 0;
  min_ = max_ = kNaN;
  sum_ = sum_compensation_ = 0.0;
}

double Histogram::min() const
{
  return count() > 0 ? min_ : kNaN;
}

double Histogram::max() const
{
  return count() > 0 ? max_ : kNaN;
}

double Histogram::mean() const
{
  return count() > 0 ? (sum_ + sum_compensation_) / static_cast<double>(count()) : kNaN;
}

std::vector<Histogram::Segment> Histogram::segments() const
{
  std::vector<Segment> s;
  s.reserve(counts_.size() + 2);
  s.push_back({min_, lo_, underflow_});
  for (int i = 0; i < bins(); ++i)
    s.push_back({binEdge(i), binEdge(i + 1), counts_[static_cast<std::size_t>(i)]});
  s.push_back({hi_, max_, overflow_});
  return s;
}

double Histogram::quantile(double q) const
{
  if (!(q >= 0.0 && q <= 1.0))
    throw std::invalid_argument("histogram: quantile " + fullPrecisionText(q) + " is not in [0, 1]");
  const std::uint64_t total = count();
  if (total == 0)
    return kNaN;
  const double r = q * static_cast<double>(total);
  double before = 0.0;
  double value = max_;
  for (const Segment& s : segments())
  {
    if (s.n == 0)
      continue;
    const double after = before + static_cast<double>(s.n);
    if (after >= r)
    {
      value = s.a + (r - before) / static_cast<double>(s.n) * (s.b - s.a);
      break;
    }
    before = after;
  }
  return std::clamp(value, min_, max_);
}

double Histogram::fractionBelow(double x) const
{
  const std::uint64_t total = count();
  if (total == 0 || std::isnan(x))
    return kNaN;
  if (x <= min_)
    return 0.0;
  if (x > max_)
    return 1.0;
  double below = 0.0;
  for (const Segment& s : segments())
  {
    if (s.n == 0)
      continue;
    if (x >= s.b)
    {
      below += static_cast<double>(s.n);
      continue;
    }
    if (x > s.a)
      below += static_cast<double>(s.n) * (x - s.a) / (s.b - s.a);
    break;
  }
  return below / static_cast<double>(total);
}

std::string histogramYaml(const Histogram& h, const std::string& indent, double scale, const std::string& unit)
{
  if (!(scale > 0.0) || !std::isfinite(scale))
    throw std::invalid_argument("histogramYaml: scale must be finite and > 0 (got " + fullPrecisionText(scale) + ")");
  auto v = [scale](double x) { return yamlNumber(x * scale); };
  std::string out;
  out += indent + "unit: " + yamlQuoted(unit) + "\n";
  out += indent + "count: " + std::to_string(h.count()) + "  # finite samples\n";
  out += indent + "underflow: " + std::to_string(h.underflow()) + "  # below lo\n";
  out += indent + "overflow: " + std::to_string(h.overflow()) + "  # above hi\n";
  out += indent + "non_finite: " + std::to_string(h.nonFinite()) + "\n";
  out += indent + "min: " + v(h.min()) + "\n";
  out += indent + "max: " + v(h.max()) + "\n";
  out += indent + "mean: " + v(h.mean()) + "\n";
  out += indent + "quantiles: {p50: " + v(h.quantile(0.5)) + ", p90: " + v(h.quantile(0.9)) +
         ", p95: " + v(h.quantile(0.95)) + ", p99: " + v(h.quantile(0.99)) + "}\n";
  out += indent + "lo: " + v(h.lo()) + "\n";
  out += indent + "hi: " + v(h.hi()) + "\n";
  out += indent + "edges: [";
  for (int i = 0; i <= h.bins(); ++i)
    out += (i > 0 ? ", " : "") + v(h.binEdge(i));
  out += "]\n";
  out += indent + "counts: [";
  for (int i = 0; i < h.bins(); ++i)
    out += (i > 0 ? ", " : "") + std::to_string(h.binCount(i));
  out += "]\n";
  return out;
}
}  // namespace scanhead
