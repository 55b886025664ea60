/// \file benchmark_contour_error.hpp
/// \brief Throughput of the contour error (SPEC §5) on a long hatch, for scanhead_benchmark.
///
/// A header (inline), not a .cpp: every src/tools/*.cpp is an executable. Not a test: wall-clock
/// times (steady_clock), run it on a quiet machine.
#pragma once

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <ostream>
#include <vector>

#include "scanhead/metrics/contour_error.hpp"

namespace scanhead
{
namespace contour_error_benchmark
{
using Clock = std::chrono::steady_clock;

inline double seconds(Clock::duration d)
{
  return std::chrono::duration<double>(d).count();
}

/// \brief Rates [points/s] of chunks of equal size: mean over the whole, worst and best chunk.
struct Rates
{
  double total_s = 0.0;
  std::size_t points = 0;
  double worst = std::numeric_limits<double>::infinity();
  double best = 0.0;
  void chunk(std::size_t n, double s)
  {
    total_s += s;
    points += n;
    if (s > 0.0)
    {
      worst = std::min(worst, n / s);
      best = std::max(best, n / s);
    }
  }
  double mean() const { return total_s > 0.0 ? points / total_s : 0.0; }
};

/// \brief Commanded serpentine hatch around the origin: lines of 50 mm along x, 100 µm apart,
/// 1 m/s sampled every 10 µs (10 µm steps), the 100 µm step to the next line in 10 samples.
inline Eigen::Vector2d hatchPoint(std::size_t k)
{
  constexpr std::size_t per_line = 5000;  // samples along a line
  constexpr std::size_t per_turn = 10;    // samples of the step to the next line
  constexpr double step = 1e-5, spacing = 1e-4;
  const std::size_t period = per_line + per_turn;
  const std::size_t line = k / period, at = k % period;
  const bool backwards = line % 2 == 1;
  double x, y = line * spacing;
  if (at < per_line)
    x = (backwards ? double(per_line - at) : double(at)) * step;
  else
  {
    x = backwards ? 0.0 : per_line * step;
    y += (at - per_line) * spacing / per_turn;
  }
  return Eigen::Vector2d(x - 0.5 * per_line * step, y - 0.05);
}

struct SizeResult
{
  std::size_t points = 0;
  double fill_rate = 0, build_rate = 0;
  Rates nearest, nearest_hinted, same_instant;
  double path_bytes_per_point = 0, index_bytes_per_point = 0, segments_per_query = 0;
  std::size_t grids = 0;
  ContourErrorStats stats_nearest, stats_hinted, stats_same;  ///< hinted must equal nearest
};

/// \brief One size: actual = commanded through a first-order lag of τ = 50 µs (the spot trails by
/// 50 µm and rounds the turns); same instant with the delay compensated, j = k + 5.
inline SizeResult runSize(std::size_t n)
{
  SizeResult r;
  r.points = n;
  const double ts = 1e-5, tau = 5e-5;
  const std::size_t lag = 5;
  const double alpha = 1.0 - std::exp(-ts / tau);
  PathPoints commanded, actual;
  commanded.reserve(n);
  actual.reserve(n);
  for (std::size_t k = 0; k < n; ++k)
    commanded.add(hatchPoint(k));

  const auto t0 = Clock::now();
  Eigen::Vector2d y = commanded.point(0);
  for (std::size_t k = 0; k < n; ++k)
  {
    y += alpha * (commanded.point(k) - y);
    actual.add(y);
  }
  const auto t1 = Clock::now();
  const NearestPathIndex index(actual);
  const auto t2 = Clock::now();
  r.fill_rate = n / seconds(t1 - t0);
  r.build_rate = n / seconds(t2 - t1);
  r.path_bytes_per_point = double(actual.memoryBytes()) / n;
  r.index_bytes_per_point = double(index.memoryBytes()) / n;
  r.grids = index.gridCount();

  const std::size_t last = n > lag ? n - lag : 0;  // commanded points with a same-instant sample
  const std::size_t chunks = 50, chunk = std::max<std::size_t>(1, last / chunks);
  NearestPathHint hint;  // as the layer metrics query: the last leaf kept from point to point
  for (std::size_t begin = 0; begin < last; begin += chunk)
  {
    const std::size_t end = std::min(last, begin + chunk);
    auto a = Clock::now();
    for (std::size_t k = begin; k < end; ++k)
      r.stats_same.add(sameInstantDistance(actual, k + lag, commanded.point(k)));
    auto b = Clock::now();
    for (std::size_t k = begin; k < end; ++k)
      r.stats_nearest.add(index.distance(commanded.point(k)));
    auto c = Clock::now();
    for (std::size_t k = begin; k < end; ++k)
    {
      const Eigen::Vector2d p = commanded.point(k);
      r.stats_hinted.add(index.distance(p, sameInstantDistance(actual, k + lag, p), nullptr, &hint));
    }
    auto d = Clock::now();
    r.same_instant.chunk(end - begin, seconds(b - a));
    r.nearest.chunk(end - begin, seconds(c - b));
    r.nearest_hinted.chunk(end - begin, seconds(d - c));
  }
  NearestPathWork work;
  const std::size_t probes = std::min<std::size_t>(last, 100000);
  for (std::size_t q = 0; q < probes; ++q)
    index.distance(commanded.point(q * (last / std::max<std::size_t>(probes, 1))),
                   std::numeric_limits<double>::infinity(), &work);
  r.segments_per_query = probes ? double(work.segments_tested) / probes : 0.0;
  return r;
}

}  // namespace contour_error_benchmark

/// \brief Times the contour error on a serpentine hatch of \p points samples and of points / 10:
/// path fill, index build, queries of the nearest path (a), the same one with the same-instant
/// error as an upper bound, and the same instant (b), in points per second (mean over the whole
/// run, worst and best of 50 chunks), then the (a)/(b) cost ratio and the rates at both sizes
/// (an O(n log n) method would lose a log factor per decade; this one should hold its rate).
inline void benchmarkContourError(std::ostream& out, std::size_t points)
{
  using namespace contour_error_benchmark;
  const std::size_t small_n = std::max<std::size_t>(points / 10, 1000), large_n = std::max(points, small_n);
  out << "\ncontour error (SPEC 5): serpentine hatch 50 mm lines, 100 um spacing, 1 m/s, Ts = 10 us;\n"
      << "actual = commanded through a 50 us first-order lag, same instant at j = k + 5\n";
  SizeResult results[2] = {runSize(small_n), runSize(large_n)};
  for (const SizeResult& r : results)
  {
    char head[160];
    std::snprintf(head, sizeof head,
                  "\n%zu points: fill %.1f Mpoints/s, index build %.1f Mpoints/s, path %.2f B/point, "
                  "index %.2f B/point, %zu grids\n",
                  r.points, r.fill_rate * 1e-6, r.build_rate * 1e-6, r.path_bytes_per_point, r.index_bytes_per_point,
                  r.grids);
    out << head;
    char cols[160];
    std::snprintf(cols, sizeof cols, "  %-34s %12s %12s %12s\n", "query", "Mpoints/s", "worst", "best");
    out << cols;
    const auto row = [&](const char* name, const Rates& rates) {
      char buf[160];
      std::snprintf(buf, sizeof buf, "  %-34s %12.2f %12.2f %12.2f\n", name, rates.mean() * 1e-6, rates.worst * 1e-6,
                    rates.best * 1e-6);
      out << buf;
    };
    row("(a) nearest path", r.nearest);
    row("(a) nearest path, (b) as bound", r.nearest_hinted);
    row("(b) same instant", r.same_instant);
    char tail[256];
    std::snprintf(tail, sizeof tail,
                  "  cost (a)/(b): %.1fx; %.1f segments tested per (a) query; (a) mean %.3f um, "
                  "max %.3f um, under 10 um %.4f%s; (b) mean %.3f um, max %.3f um\n",
                  r.same_instant.mean() / r.nearest.mean(), r.segments_per_query, r.stats_nearest.mean() * 1e6,
                  r.stats_nearest.max() * 1e6, r.stats_nearest.shareUnder(10e-6),
                  r.stats_hinted == r.stats_nearest ? "" : " (BOUNDED RESULT DIFFERS)", r.stats_same.mean() * 1e6,
                  r.stats_same.max() * 1e6);
    out << tail;
  }
  char scale[256];
  std::snprintf(scale, sizeof scale,
                "scaling n/10 -> n: index build rate x%.2f, (a) query rate x%.2f, (b) x%.2f "
                "(1.00: linear total time)\n",
                results[1].build_rate / results[0].build_rate, results[1].nearest.mean() / results[0].nearest.mean(),
                results[1].same_instant.mean() / results[0].same_instant.mean());
  out << scale;
}
}  // namespace scanhead
