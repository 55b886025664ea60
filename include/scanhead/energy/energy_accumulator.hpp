/// \file energy_accumulator.hpp
/// \brief Integrates the spot's irradiance along the spot stream into the sparse energy map (SPEC §5).
#pragma once

#include <Eigen/Core>
#include <atomic>
#include <cstdint>
#include <memory>
#include <vector>

#include "scanhead/common/chunk.hpp"
#include "scanhead/common/chunk_sequencer.hpp"
#include "scanhead/energy/energy_config.hpp"
#include "scanhead/energy/node_chain.hpp"
#include "scanhead/energy/node_deposit.hpp"
#include "scanhead/energy/sampled_deposit.hpp"
#include "scanhead/energy/spot_footprint.hpp"
#include "scanhead/energy/stroke_deposit.hpp"
#include "scanhead/energy/stroke_merger.hpp"
#include "scanhead/energy/tiled_energy_map.hpp"

namespace scanhead
{
/// \brief E(p) = ∫ I(p − x_exp(t), t) dt on a TiledEnergyMap, I the footprint of spot_footprint.hpp.
///
/// The energy of sample k, P_k·Ts, is spread uniformly in time along the segment from the actual spot k to k+1, with
/// the footprint of sample k (its beam direction). energy.method chooses how:
/// - trapezoid (default): the time integral along the polyline by the trapezoid rule at its vertices, each shifted by
///   the Euler–Maclaurin term of the kinks (node_chain.hpp), windows of consecutive nodes drawn as sums of separable
///   Gaussians (node_deposit.hpp);
/// - exact: the closed form of segment_integral.hpp; consecutive segments of one straight, constant-velocity,
///   constant-power stroke are merged (stroke_merger.hpp) and drawn once (stroke_deposit.hpp);
/// - sampled: point-sampled at sub-steps (sampled_deposit.hpp), the reference.
/// Both truncate the footprint at truncation_radii·w_major and normalise the drawn weights to the energy (conserved
/// to rounding; the share off the map is added to energyOutsideMap()). The last sample stays pending until the next
/// one arrives, and the pending stroke (exact) or chain segment and open window (trapezoid) too, so chunking does not
/// change the result, bit for bit; finish() deposits the last sample as a stationary dwell.
///
/// Stream anomalies: samples whose global index was already seen (overlap, late chunk) are
/// skipped; at a gap the pending sample is deposited as a dwell (its successor is unknown).
/// Samples with zero power deposit nothing.
class EnergyAccumulator
{
public:
  /// \throws ConfigError from config.validate() or the map size check
  EnergyAccumulator(const EnergyConfig& config, const Eigen::Vector2d& min_corner, const Eigen::Vector2d& max_corner);
  void reset();
  /// \throws NumericalError on a non-finite position or direction of a sample that carries power
  void process(const SpotChunk& chunk);
  /// \brief Deposits the last pending sample (call once at the end of the stream).
  void finish();

  /// \brief process() in three steps, for a caller with a second thread (EnergyStage, stream.threads = 2): stage()
  /// merges the chunk's samples into strokes (exact) or windows of nodes (trapezoid) without drawing them (sampled:
  /// deposits them); weighStaged() computes the staged strokes' (windows') weights, and any number of threads may run
  /// it at once (each takes the next stroke not yet taken); applyStaged() adds them to the map in stream order once
  /// every weighStaged() has returned. The map is the one process() gives, bit for bit: each stroke's weights are the
  /// same floats whichever thread computed them. At most kMaxStagedStrokes strokes or kMaxStagedPixels weights are
  /// staged; beyond, stage() draws them itself. If stage() throws, what it staged is still to be weighed and applied
  /// (process() does).
  ///
  /// Pipelined (EnergyStage): retireStaged() sets the weighed batch aside instead of applying it, and applyReady()
  /// adds it to the map later, on this thread, while other threads weigh the next batch (weighing reads only the map's
  /// geometry). Every step that adds to the map (applyStaged, a draw inside stage(), finish) first applies the batch
  /// set aside, so the strokes reach the map in stream order: the same floats as process(). Up to two batches are then
  /// held (2 × kMaxStagedPixels weights).
  void stage(const SpotChunk& chunk);
  void weighStaged();
  void applyStaged();
  void retireStaged();
  void applyReady();
  static constexpr std::size_t kMaxStagedStrokes = 1024;
  static constexpr double kMaxStagedPixels = 8.0 * 1024 * 1024;  ///< 32 MB of float weights
  const TiledEnergyMap& map() const { return map_; }
  double energyOutsideMap() const { return outside_j_; }  ///< footprint energy that fell off the map [J]
  /// \brief Samples that carried energy to the map (every method).
  std::uint64_t samplesDeposited() const { return samples_; }
  /// \brief exact: strokes drawn (samplesDeposited() / strokesDeposited() samples merged per stroke); trapezoid:
  /// windows of nodes drawn; sampled: 0.
  std::uint64_t strokesDeposited() const { return strokes_; }
  /// \brief trapezoid: nodes drawn; else 0.
  std::uint64_t nodesDeposited() const { return nodes_; }
  /// \brief exact, trapezoid: pixel weights added to the map (the method's cost); sampled: 0.
  std::uint64_t pixelsDrawn() const { return stroke_deposit_.pixelsDrawn(); }

private:
  /// \brief The segment of \p from (its energy over \p period_s) to \p to.
  void deposit(const SpotSample& from, const Eigen::Vector2d& to, double period_s);
  void drawStroke(const Stroke& stroke);  ///< stages it
  void drawStaged();                      ///< weighs and applies the staged strokes on this thread
  void flushStroke();                     ///< ends the pending stroke (exact) or chain (trapezoid)
  void takeNodes();                       ///< the chain's completed nodes into windows
  void closeWindow();                     ///< stages the open window
  /// \brief After a stroke or window was staged (~\p pixels weights): its weights slot; the staged batch drawn here
  /// once it holds kMaxStagedStrokes items or kMaxStagedPixels weights.
  void bookStaged(double pixels);
  std::size_t stagedCount() const;  ///< strokes or windows staged
  void clearStaged();               ///< after a batch is applied or retired
  enum class Method
  {
    kTrapezoid,
    kExact,
    kSampled
  };
  EnergyConfig config_;
  SpotFootprintModel footprint_;  ///< the footprint of a sample's beam direction
  Method method_ = Method::kTrapezoid;
  TiledEnergyMap map_;
  bool has_pending_ = false;
  SpotSample pending_;
  double period_s_ = 0.0;    ///< period of the chunk that delivered the pending sample [s]
  ChunkSequencer sequence_;  ///< which samples are new, where the stream broke
  double outside_j_ = 0.0;
  SampledDeposit sampled_;
  StrokeMerger merger_;
  StrokeDeposit stroke_deposit_;
  NodeChain chain_;
  NodeDeposit node_deposit_;
  std::uint64_t samples_ = 0, strokes_ = 0, nodes_ = 0;
  std::vector<Stroke> staged_;
  /// trapezoid: the staged windows' nodes, window k ending at window_ends_[k]; nodes from open_begin_ on form the
  /// open window (not yet staged)
  std::vector<QuadratureNode> staged_nodes_;
  std::vector<std::size_t> window_ends_;
  std::size_t open_begin_ = 0;
  NodeDeposit::OpenWindow open_;
  std::vector<StrokeWeights> staged_weights_;  ///< slot k: staged_[k]'s weights (slots kept between batches)
  std::vector<StrokeWeights> ready_weights_;   ///< the batch retireStaged() set aside, in stream order
  std::size_t ready_count_ = 0;                ///< its strokes (slots beyond are spare)
  std::size_t ready_applied_ = 0;              ///< of them, added to the map (an error may stop part-way)
  std::size_t staged_applied_ = 0;             ///< staged strokes added to the map (likewise)
  double staged_pixels_ = 0.0;                 ///< upper estimate of the staged strokes' weights
  /// Next staged stroke to weigh (on the heap: keeps the accumulator movable).
  std::unique_ptr<std::atomic<std::size_t>> next_to_weigh_ = std::make_unique<std::atomic<std::size_t>>(0);
};
}  // namespace scanhead
