/// \file histogram.hpp
/// \brief Fixed-bin histogram for the reports (per-axis angle errors, contour errors; SPEC §5),
/// with exact counts, min, max and mean, quantiles linear within a bin, and a YAML fragment writer.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace scanhead
{
/// \brief \p bins equal bins over [lo, hi]: bin i holds edge(i) ≤ x < edge(i+1), the last bin also
/// holds x = hi, with edge(i) = lo + (hi − lo)·i / bins (edge(bins) = hi exactly).
///
/// Every sample is counted somewhere, never dropped silently: x < lo in underflow(), x > hi in
/// overflow(), NaN and ±inf in nonFinite() only. count(), min(), max() and mean() are over the finite
/// samples (in range, underflow and overflow; mean() exact up to a compensated sum, not from the bin
/// centres).
///
/// quantile() and fractionBelow() treat the samples as spread evenly within their bin, and the
/// underflow (overflow) samples as spread evenly over [min, lo) ((hi, max]); both are exact at the
/// bin edges and inverse to each other.
class Histogram
{
public:
  /// \throws ConfigError naming the values if lo, hi are not finite with lo < hi and hi − lo finite,
  /// if bins is not in 1 .. 2^24, or if the range is too narrow for distinct edges in double
  Histogram(double lo, double hi, int bins);

  /// \brief Counts one sample (any value: see the class comment for where it goes).
  void add(double x);
  /// \brief Adds the counts and statistics of \p other.
  /// \throws std::invalid_argument unless other has the same lo, hi and bins (bit for bit)
  void merge(const Histogram& other);
  /// \brief Clears every count (the bins stay).
  void reset();

  double lo() const { return lo_; }
  double hi() const { return hi_; }
  int bins() const { return static_cast<int>(counts_.size()); }
  /// \brief edge(i), i = 0 .. bins().
  /// \throws std::out_of_range if i is not in 0 .. bins()
  double binEdge(int i) const;
  /// \throws std::out_of_range if i is not in 0 .. bins() − 1
  std::uint64_t binCount(int i) const;
  const std::vector<std::uint64_t>& binCounts() const { return counts_; }

  std::uint64_t count() const { return in_range_ + underflow_ + overflow_; }  ///< finite samples
  std::uint64_t inRange() const { return in_range_; }                         ///< lo ≤ x ≤ hi
  std::uint64_t underflow() const { return underflow_; }                      ///< x < lo
  std::uint64_t overflow() const { return overflow_; }                        ///< x > hi
  std::uint64_t nonFinite() const { return non_finite_; }                     ///< NaN, ±inf

  double min() const;   ///< smallest finite sample; NaN if count() = 0
  double max() const;   ///< largest finite sample; NaN if count() = 0
  double mean() const;  ///< mean of the finite samples; NaN if count() = 0

  /// \brief The value below which a share \p q of the finite samples lies:
  /// with r = q·count(), the first non-empty bin [a, b) holding n samples, c before it, with
  /// c + n ≥ r gives
  /// \f[ Q(q) = a + \frac{r - c}{n}\,(b - a), \f]
  /// clamped to [min, max] (so Q(0) = min, Q(1) = max). NaN if count() = 0.
  /// \throws std::invalid_argument if q is not in [0, 1]
  double quantile(double q) const;
  /// \brief Share of the finite samples below \p x: exact (the share of samples < x) when x is a
  /// bin edge, linear within a bin, 0 for x ≤ min and 1 for x > max. NaN if count() = 0 or x is NaN.
  double fractionBelow(double x) const;

private:
  struct Segment
  {
    double a, b;
    std::uint64_t n;
  };
  /// \brief Underflow [min, lo), the bins, overflow (hi, max]: the pieces quantile() walks.
  std::vector<Segment> segments() const;
  int binOf(double x) const;

  double lo_, hi_, span_;
  double scale_ = 0.0;  ///< bins / span: binOf()'s first guess
  std::vector<std::uint64_t> counts_;
  std::vector<double> edges_;  ///< binEdge(0 … bins), computed once (binOf compares against them)
  std::uint64_t in_range_ = 0, underflow_ = 0, overflow_ = 0, non_finite_ = 0;
  double min_, max_;
  double sum_ = 0.0, sum_compensation_ = 0.0;  ///< Neumaier sum of the finite samples
};

/// \brief A YAML block mapping of the histogram, each line prefixed by \p indent, values
/// multiplied by \p scale and given in \p unit (e.g. scale 1e6, unit "urad" for an angle in rad),
/// numbers with 17 significant digits (fullPrecisionText), NaN (empty histogram) as .nan:
/// \code
/// unit: "urad"
/// count: 1000        # finite samples
/// underflow: 0       # below lo
/// overflow: 2        # above hi
/// non_finite: 0
/// min: -12.5
/// max: 81.25
/// mean: 3.0000000000000004
/// quantiles: {p50: 2.5, p90: 10, p95: 12.5, p99: 20}
/// lo: -50
/// hi: 50
/// edges: [-50, -40, ..., 50]   # bins + 1 values
/// counts: [0, 3, ..., 0]       # bins values
/// \endcode
/// Use it under a key: `out << "angle_error_x:\n" << histogramYaml(h, "  ", 1e6, "urad");`
/// \throws std::invalid_argument if scale is not finite and > 0
std::string histogramYaml(const Histogram& histogram, const std::string& indent, double scale, const std::string& unit);
}  // namespace scanhead
