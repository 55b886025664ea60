/// \file energy_accumulator.cpp
/// \brief The Gaussian-spot accumulator on the sparse map (SPEC §5): the stream's bookkeeping, the method chosen.
#include "scanhead/energy/energy_accumulator.hpp"

#include <sstream>

#include "deposit_checks.hpp"
#include "scanhead/common/errors.hpp"

namespace scanhead
{
namespace
{
const EnergyConfig& validated(const EnergyConfig& config)
{
  config.validate();
  return config;
}
}  // namespace

EnergyAccumulator::EnergyAccumulator(const EnergyConfig& config, const Eigen::Vector2d& min_corner,
                                     const Eigen::Vector2d& max_corner)
  : config_(validated(config))
  , footprint_(config_)
  , method_(config.method == "exact"     ? Method::kExact
            : config.method == "sampled" ? Method::kSampled
                                         : Method::kTrapezoid)
  , map_(min_corner, max_corner, config.pixel_m, config.tile_cache_bytes, config.spill_dir)
  , sampled_(config)
  , merger_(config.stroke_tolerance_m, config.pixel_m)
  , stroke_deposit_(config)
  , node_deposit_(config)
{
  // The stencil of the nominal spot must be drawable (a larger one from defocus is checked per sample).
  const double rs = config_.truncation_radii * 0.5 * config_.spot_diameter_m / config_.pixel_m;
  if (rs > energy_detail::kMaxStencilRadius)
  {
    std::ostringstream msg;
    msg << "energy.pixel_m = " << config_.pixel_m << " m is too fine for the spot (stencil radius " << rs << " pixels)";
    throw ConfigError(msg.str());
  }
}

void EnergyAccumulator::reset()
{
  map_.clear();
  has_pending_ = false;
  sequence_.reset();
  period_s_ = 0.0;
  outside_j_ = 0.0;
  merger_.reset();
  chain_.reset();
  staged_.clear();
  staged_nodes_.clear();
  window_ends_.clear();
  open_begin_ = 0;
  open_ = NodeDeposit::OpenWindow();
  staged_pixels_ = 0.0;
  ready_count_ = ready_applied_ = staged_applied_ = 0;
  next_to_weigh_->store(0);
  stroke_deposit_.resetCounters();
  samples_ = strokes_ = nodes_ = 0;
}

void EnergyAccumulator::process(const SpotChunk& chunk)
{
  try
  {
    stage(chunk);
  }
  catch (...)
  {
    drawStaged();  // the strokes merged before the error
    throw;
  }
  drawStaged();
}

void EnergyAccumulator::stage(const SpotChunk& chunk)
{
  const bool started = sequence_.started();
  const ChunkAdmission admission = sequence_.admit(chunk.first_index, chunk.samples.size());
  if (admission.broken(started) && has_pending_)
  {
    finish();  // gap: the pending sample's successor is lost, deposit it where it stands
  }
  // Samples before admission.skip were already accumulated (overlap or late chunk).
  try
  {
    for (std::size_t k = admission.skip; k < chunk.samples.size(); ++k)
    {
      const SpotSample& s = chunk.samples[k];
      if (has_pending_)
      {
        if (pending_.power_w > 0.0)
          deposit(pending_, s.actual, period_s_);
        else
          flushStroke();  // a stroke or chain never runs through a sample without power
      }
      pending_ = s;
      period_s_ = chunk.period_s;
      has_pending_ = true;
    }
  }
  catch (...)
  {
    // The rest of the chunk is lost but already counted as taken: never join across it.
    has_pending_ = false;
    flushStroke();  // what was merged before the bad sample is deposited, as the sampled method deposits it
    throw;
  }
}

void EnergyAccumulator::finish()
{
  if (has_pending_ && pending_.power_w > 0.0)
  {
    deposit(pending_, pending_.actual, period_s_);
  }
  has_pending_ = false;
  flushStroke();
  closeWindow();
  drawStaged();
  map_.finishWrites();
}

void EnergyAccumulator::deposit(const SpotSample& from, const Eigen::Vector2d& to, double period_s)
{
  ++samples_;
  if (method_ == Method::kSampled)
  {
    sampled_.deposit(map_, from, to, from.power_w * period_s, outside_j_);
    return;
  }
  // The checks of the sampled method, with its messages, at the same sample.
  const double length = (to - from.actual).norm();
  energy_detail::requireFiniteSegment(from.actual, to, length);
  const SpotFootprint fp = footprint_(from.direction);
  energy_detail::substepsOf(length, config_, fp);
  energy_detail::stencilRadius(config_, fp, map_.pixel());
  if (method_ == Method::kTrapezoid)
  {
    chain_.add(from.actual, to, from.power_w, period_s, fp);
    takeNodes();
    return;
  }
  Stroke done;
  if (merger_.add(from.actual, to, from.power_w, period_s, fp, done))
    drawStroke(done);
}

void EnergyAccumulator::flushStroke()
{
  if (method_ == Method::kTrapezoid)
  {
    chain_.flush();
    takeNodes();
    return;
  }
  Stroke done;
  if (method_ == Method::kExact && merger_.flush(done))
    drawStroke(done);
}

void EnergyAccumulator::takeNodes()
{
  QuadratureNode node;
  while (chain_.next(node))
  {
    if (open_.count > 0 && !node_deposit_.joins(open_, node, map_.pixel()))
      closeWindow();
    node_deposit_.add(open_, node, map_.pixel());
    staged_nodes_.push_back(node);
    ++nodes_;
  }
}

void EnergyAccumulator::closeWindow()
{
  if (staged_nodes_.size() == open_begin_)
    return;
  ++strokes_;
  window_ends_.push_back(staged_nodes_.size());
  // Weights of the window: at most the box of its centres grown by a footprint's square (its rows' spans are kept).
  const double p = map_.pixel();
  const double reach = 2.0 * config_.truncation_radii * open_.major_radius_m / p + 2.0;
  const Eigen::Vector2d box = (open_.hi - open_.lo) / p;
  open_begin_ = staged_nodes_.size();
  open_ = NodeDeposit::OpenWindow();
  bookStaged((box.x() + reach + 16.0) * (box.y() + reach));
}

void EnergyAccumulator::bookStaged(double pixels)
{
  const std::size_t count = stagedCount();
  if (staged_weights_.size() < count)
    staged_weights_.emplace_back();
  staged_pixels_ += pixels;
  if (count >= kMaxStagedStrokes || staged_pixels_ >= kMaxStagedPixels)
    drawStaged();  // bounded memory whatever the chunk size
}

std::size_t EnergyAccumulator::stagedCount() const
{
  return method_ == Method::kTrapezoid ? window_ends_.size() : staged_.size();
}

void EnergyAccumulator::clearStaged()
{
  staged_.clear();
  // The open window's nodes move to the front.
  staged_nodes_.erase(staged_nodes_.begin(), staged_nodes_.begin() + static_cast<std::ptrdiff_t>(open_begin_));
  window_ends_.clear();
  open_begin_ = 0;
  staged_pixels_ = 0.0;
  next_to_weigh_->store(0);
}

void EnergyAccumulator::drawStroke(const Stroke& stroke)
{
  ++strokes_;
  staged_.push_back(stroke);
  // Weights of the capsule: ≤ (2R/p + 2) rows of ≤ (L + 2R)/p + 2 pixels, plus a block of 8 a row.
  const double p = map_.pixel();
  const double reach = 2.0 * config_.truncation_radii * stroke.footprint.major_radius_m / p + 2.0;
  bookStaged(reach * (stroke.displacement().norm() / p + reach + 8.0));
}

void EnergyAccumulator::weighStaged()
{
  std::atomic<std::size_t>& next = *next_to_weigh_;
  const std::size_t count = stagedCount();
  for (std::size_t k = next.fetch_add(1); k < count; k = next.fetch_add(1))
  {
    if (method_ == Method::kTrapezoid)
    {
      const std::size_t begin = k == 0 ? 0 : window_ends_[k - 1];
      node_deposit_.weigh(map_, staged_nodes_.data() + begin, window_ends_[k] - begin, staged_weights_[k]);
    }
    else
      stroke_deposit_.weigh(map_, staged_[k], staged_weights_[k]);
  }
}

namespace
{
/// \brief Adds weights \p done … \p count − 1 of \p batch to the map in order, \p done counting them (an error
/// part-way, e.g. of the spill file, leaves it at the stroke that failed: a retry never adds a stroke twice); a slot
/// grown large is freed after use.
void applyBatch(StrokeDeposit& deposit, TiledEnergyMap& map, std::vector<StrokeWeights>& batch, std::size_t count,
                std::size_t& done, double& outside_j)
{
  constexpr std::size_t kKeptSlotFloats = std::size_t{1} << 16;
  for (; done < count; ++done)
  {
    deposit.apply(map, batch[done], outside_j);
    if (batch[done].weights.size() > kKeptSlotFloats)
      batch[done] = StrokeWeights();
  }
}
}  // namespace

void EnergyAccumulator::applyStaged()
{
  applyReady();  // the batch set aside came first in the stream
  applyBatch(stroke_deposit_, map_, staged_weights_, stagedCount(), staged_applied_, outside_j_);
  staged_applied_ = 0;
  clearStaged();
}

void EnergyAccumulator::retireStaged()
{
  applyReady();  // at most one batch waits
  std::swap(staged_weights_, ready_weights_);
  ready_count_ = stagedCount();
  ready_applied_ = staged_applied_;  // 0: a batch is retired whole
  staged_applied_ = 0;
  clearStaged();
}

void EnergyAccumulator::applyReady()
{
  applyBatch(stroke_deposit_, map_, ready_weights_, ready_count_, ready_applied_, outside_j_);
  ready_count_ = ready_applied_ = 0;
}

void EnergyAccumulator::drawStaged()
{
  weighStaged();
  applyStaged();
}
}  // namespace scanhead
