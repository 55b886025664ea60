/// \file layer_quality.cpp
#include "scanhead/metrics/layer_quality.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>

#include "scanhead/common/segment_distance.hpp"
#include "scanhead/common/side_thread.hpp"
#include "scanhead/metrics/first_nearest.hpp"
#include "scanhead/metrics/nearest_path_index.hpp"

namespace scanhead
{
LayerQuality::LayerQuality(const EnergyConfig& config, const PathTimeline& timeline, const Job& job, double lag_s,
                           std::uint64_t total_samples, const Eigen::Vector2d& min_corner,
                           const Eigen::Vector2d& max_corner)
  : config_(config)
  , timeline_(timeline)
  , fill_(min_corner, max_corner, config.spot_diameter_m)
  , path_(min_corner)
{
  contour_polyline_.reserve(job.polylines.size());
  for (const Polyline& line : job.polylines)
    contour_polyline_.push_back(line.type == PolylineType::Mark && line.role == PolylineRole::Contour);
  report_.lag_s = lag_s;
  report_.layer_time_s = timeline.duration();
  report_.fill_pitch_m = config.spot_diameter_m;
  keep_path_ = total_samples <= config.contour_max_samples;
  if (keep_path_)
    path_.reserve(static_cast<std::size_t>(total_samples));
  report_.nearest_measured = keep_path_;
}

LayerQuality::~LayerQuality() = default;

LayerQuality::Command LayerQuality::commandAt(std::uint64_t k, PathTimeline::Cursor& cursor) const
{
  Command c;
  if (k >= program_samples_)
    return c;
  const double t = static_cast<double>(k) * period_s_;
  const std::size_t segment = timeline_.segmentAt(t, cursor);
  // PathTimeline::positionAt on the segment just found (one search, not two).
  if (!(t > 0.0))
    c.point = timeline_.startPoint();
  else if (segment == PathTimeline::npos)
    c.point = timeline_.endPoint();
  if (segment == PathTimeline::npos)
    return c;
  const PathSegment& s = timeline_.segments()[segment];
  if (t > 0.0)
    c.point = s.pointAt(t);
  if (!s.mark)
    c.kind = Kind::Jump;
  else
    c.kind = s.polyline < contour_polyline_.size() && contour_polyline_[s.polyline] ? Kind::Contour : Kind::Hatch;
  c.speed_mps = s.dwell || s.delay ? 0.0 : s.speed_mps;
  return c;
}

const LayerQuality::Command& LayerQuality::cachedCommand(std::uint64_t k, PathTimeline::Cursor& cursor)
{
  const std::size_t slot = static_cast<std::size_t>(k & (command_cache_.size() - 1));
  if (command_cache_k_[slot] != k)
  {
    command_cache_[slot] = commandAt(k, cursor);
    command_cache_k_[slot] = k;
  }
  return command_cache_[slot];
}

void LayerQuality::addTo(ContourErrorSplit& split, Kind kind, double error_m)
{
  switch (kind)
  {
    case Kind::Contour:
      split.mark.add(error_m);
      split.contour.add(error_m);
      break;
    case Kind::Hatch:
      split.mark.add(error_m);
      split.hatch.add(error_m);
      break;
    case Kind::Jump:
      split.jump.add(error_m);
      break;
    case Kind::None:
      break;
  }
}

Eigen::Vector2d LayerQuality::held(std::uint64_t index) const
{
  const std::size_t i = static_cast<std::size_t>(index & ring_mask_);
  return Eigen::Vector2d(ring_x_[i], ring_y_[i]);
}

void LayerQuality::hold(std::uint64_t index, const Eigen::Vector2d& p)
{
  const std::size_t i = static_cast<std::size_t>(index & ring_mask_);
  const std::size_t mirror = i + static_cast<std::size_t>(ring_mask_) + 1;
  ring_x_[i] = ring_x_[mirror] = p.x();
  ring_y_[i] = ring_y_[mirror] = p.y();
}

void LayerQuality::sameInstant(std::uint64_t k)
{
  // Command k pairs with the samples j = k + L ± N the ring holds: the nearest of them (the point of
  // least following error), then the projection on its adjacent segments.
  const Command c = cachedCommand(k, command_cursor_);
  fill_.addCommanded(c.point, c.kind == Kind::Hatch);
  const std::uint64_t centre = k + lag_samples_;
  const std::uint64_t lo = std::max(centre >= window_samples_ ? centre - window_samples_ : 0, ring_first_);
  const std::uint64_t hi = std::min(centre + window_samples_, next_index_ - 1);
  if (!started_ || lo > hi)
  {
    ++report_.unmatched_points;  // no sample of its window arrived (stream gap)
    return;
  }
  double nearest_d2 = INFINITY;
  const std::size_t start = static_cast<std::size_t>(lo & ring_mask_);  // [lo, hi] contiguous from here
  const std::uint64_t nearest =
      lo + firstNearest(ring_x_.data() + start, ring_y_.data() + start, static_cast<std::size_t>(hi - lo + 1),
                        c.point.x(), c.point.y(), nearest_d2);
  double best2 = nearest_d2;  // an isolated sample: the distance to it (squared: one root at the end, the same bits)
  if (nearest > ring_first_)
    best2 = std::min(best2, pointSegmentDistance2(c.point, held(nearest - 1), held(nearest)));
  if (nearest + 1 < next_index_)
    best2 = std::min(best2, pointSegmentDistance2(c.point, held(nearest), held(nearest + 1)));
  addTo(report_.same_instant, c.kind, std::sqrt(best2));
}

void LayerQuality::unmatched(std::uint64_t k)
{
  const Command c = cachedCommand(k, command_cursor_);
  fill_.addCommanded(c.point, c.kind == Kind::Hatch);
  ++report_.unmatched_points;
}

void LayerQuality::process(const SpotChunk& chunk)
{
  if (!started_)
  {
    period_s_ = chunk.period_s;
    lag_samples_ = static_cast<std::uint64_t>(std::llround(std::max(0.0, report_.lag_s) / period_s_));
    window_samples_ = static_cast<std::uint64_t>(std::llround(config_.same_instant_window_s / period_s_));
    report_.window_s = static_cast<double>(window_samples_) * period_s_;
    ring_size_ = 2 * window_samples_ + 3;
    std::uint64_t storage = 1;
    while (storage < ring_size_)
      storage *= 2;
    ring_mask_ = storage - 1;
    ring_x_.assign(static_cast<std::size_t>(2 * storage), 0.0);
    ring_y_.assign(static_cast<std::size_t>(2 * storage), 0.0);
    std::size_t cache = 1;
    while (cache < window_samples_ + 2)
      cache *= 2;
    command_cache_.assign(cache, Command());
    command_cache_k_.assign(cache, UINT64_MAX);
    // Commanded points: k·Ts < layer time (the same rounding as the NC's sample times).
    program_samples_ = static_cast<std::uint64_t>(std::ceil(report_.layer_time_s / period_s_ - 1e-9));
    report_.commanded_points = program_samples_;
  }
  const ChunkAdmission admission = sequence_.admit(chunk.first_index, chunk.samples.size());
  for (std::size_t n = admission.skip; n < chunk.samples.size(); ++n)  // earlier ones already seen
  {
    const std::uint64_t m = chunk.first_index + n;
    const SpotSample& s = chunk.samples[n];
    if (n == admission.skip && admission.broken(started_))
    {
      // Gap: the commands whose window meets the samples before it use those; those whose window
      // lies in the gap are unmatched; the others wait for the samples after it.
      while (next_command_ < program_samples_ && next_command_ + lag_samples_ <= next_index_ - 1 + window_samples_)
        sameInstant(next_command_++);
      while (next_command_ < program_samples_ && next_command_ + lag_samples_ + window_samples_ < m)
        unmatched(next_command_++);
      ring_first_ = m;
      fill_.breakActual();
      if (keep_path_)
        path_.breakPath();
      path_gapped_ = true;
    }
    // Angle errors over the program, speed and fill against the same-instant command.
    if (m < program_samples_)
    {
      report_.angle_error_x.add(s.angle_error.x());
      report_.angle_error_y.add(s.angle_error.y());
    }
    const Command c = cachedCommand(m >= lag_samples_ ? m - lag_samples_ : program_samples_, lagged_cursor_);
    const bool marking = s.power_w > 0.0 && (c.kind == Kind::Hatch || c.kind == Kind::Contour);
    fill_.addActual(s.actual, s.power_w > 0.0 && c.kind == Kind::Hatch);
    if (marking && c.speed_mps > 0.0 && started_ && m > ring_first_)
    {
      const double ratio = (s.actual - held(m - 1)).norm() / period_s_ / c.speed_mps;
      report_.mark_speed_ratio.add(ratio);
      speed_ratio_sum_ += ratio;
      speed_samples_ += 1.0;
    }
    if (keep_path_)
      path_.add(s.actual);
    if (!started_)
      ring_first_ = m;
    hold(m, s.actual);
    started_ = true;
    next_index_ = m + 1;
    ring_first_ = std::max(ring_first_, next_index_ > ring_size_ ? next_index_ - ring_size_ : 0);
    // Command k is complete once sample k + L + N + 1 is in (its window and the segment after it).
    while (next_command_ < program_samples_ && next_command_ + lag_samples_ + window_samples_ + 1 <= m)
      sameInstant(next_command_++);
  }
}

void LayerQuality::nearestPathPass(const NearestPathIndex& index, unsigned threads)
{
  // The queries are independent: a block's distances are computed in pieces that this thread and a side thread take in
  // turn (an atomic counter: neither waits for the other's half when a core is taken from it), and added to the
  // statistics in order by this thread while the side thread already searches the next block (double buffers: the
  // side thread never waits for the additions). The same sums, bit for bit, as one thread. A block of 2^15 points is
  // ~5 ms of searching: the hand-over costs ~0.1 % of it, and the block's buffers stay in L2.
  constexpr std::uint64_t kBlock = std::uint64_t{1} << 15;
  constexpr std::uint64_t kPiece = std::uint64_t{1} << 10;
  struct Searcher
  {
    PathTimeline::Cursor cursor;  ///< each thread's own, moving forward
    NearestPathHint hint;         ///< the leaf of its last query (consecutive points share it)
  };
  struct Results
  {
    std::vector<double> distance = std::vector<double>(static_cast<std::size_t>(kBlock));
    std::vector<Kind> kind = std::vector<Kind>(static_cast<std::size_t>(kBlock));
  };
  Results results[2];
  std::atomic<std::uint64_t> next_piece{0};
  const auto measure = [this, &index, &next_piece](std::uint64_t k0, std::uint64_t k1, Results& out,
                                                   Searcher& searcher) {
    const std::uint64_t pieces = (k1 - k0 + kPiece - 1) / kPiece;
    for (std::uint64_t piece; (piece = next_piece.fetch_add(1, std::memory_order_relaxed)) < pieces;)
    {
      const std::uint64_t from = k0 + piece * kPiece, to = std::min(k1, from + kPiece);
      for (std::uint64_t k = from; k < to; ++k)
      {
        const Command c = commandAt(k, searcher.cursor);
        const std::uint64_t j = k + lag_samples_;
        // The same-instant error on the stored path bounds the search (exact: a distance to it).
        const double bound = !path_gapped_ && j < path_.size()
                                 ? sameInstantDistance(path_, static_cast<std::size_t>(j), c.point)
                                 : INFINITY;
        out.distance[k - k0] = index.distance(c.point, bound, nullptr, &searcher.hint);
        out.kind[k - k0] = c.kind;
      }
    }
  };
  std::unique_ptr<SideThread> side =
      threads >= 2 && program_samples_ > kBlock ? std::make_unique<SideThread>() : nullptr;
  Searcher mine, other;
  const std::uint64_t blocks = (program_samples_ + kBlock - 1) / kBlock;
  // Block b: searched (by both threads) while block b − 1 is added up (by this one).
  for (std::uint64_t b = 0; b <= blocks; ++b)
  {
    const std::uint64_t k0 = b * kBlock, k1 = std::min(k0 + kBlock, program_samples_);
    Results& out = results[b % 2];
    if (b < blocks)
    {
      next_piece.store(0, std::memory_order_relaxed);
      if (side)
        side->start([&measure, k0, k1, &out, &other] { measure(k0, k1, out, other); });
    }
    if (b > 0)
    {
      const Results& done = results[(b - 1) % 2];
      const std::uint64_t d0 = (b - 1) * kBlock, d1 = std::min(d0 + kBlock, program_samples_);
      for (std::uint64_t k = d0; k < d1; ++k)
        addTo(report_.nearest_path, done.kind[k - d0], done.distance[k - d0]);
    }
    if (b < blocks)
    {
      measure(k0, k1, out, mine);
      if (side)
        side->wait();
    }
  }
}

LayerQualityReport LayerQuality::finish(unsigned threads)
{
  // The last commands pair with the last sample (one segment) or with none (unmatched).
  while (next_command_ < program_samples_)
  {
    sameInstant(next_command_++);
  }
  std::size_t index_bytes = 0;
  if (keep_path_ && !path_.empty())
  {
    const NearestPathIndex index(path_, threads);
    index_bytes = index.memoryBytes();
    nearestPathPass(index, threads);
  }
  report_.fill_cells_to_fill = fill_.cellsToFill();
  report_.fill_cells_reached = fill_.cellsReached();
  report_.fill_rate = fill_.fillRate();
  report_.fill_points_outside = fill_.pointsOutside();
  report_.mark_speed_mean_ratio = speed_samples_ > 0.0 ? speed_ratio_sum_ / speed_samples_ : NAN;
  report_.memory_bytes =
      path_.memoryBytes() + index_bytes + fill_.memoryBytes() + timeline_.segments().capacity() * sizeof(PathSegment);
  // The nearest-path pass was the path's last reader: its memory (8 B a sample, 244 MB on the THESIS layer) goes
  // before the results are written.
  path_ = PathPoints(path_.origin());
  return report_;
}
}  // namespace scanhead
