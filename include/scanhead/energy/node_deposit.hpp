/// \file node_deposit.hpp
/// \brief Windows of consecutive QuadratureNodes drawn on the map as sums of separable Gaussians (energy.method:
/// trapezoid).
#pragma once

#include <cstddef>
#include <cstdint>

#include "scanhead/energy/energy_config.hpp"
#include "scanhead/energy/node_chain.hpp"
#include "scanhead/energy/stroke_deposit.hpp"
#include "scanhead/energy/tiled_energy_map.hpp"

namespace scanhead
{
/// \brief Draws a window of nodes (node_chain.hpp): the weights e_j·G_j(r − c_j) at the pixel centres of each node's
/// square of half-side R = truncation_radii·w_major, each node normalised so that its weights sum to e_j (its energy;
/// the share on pixels off the map goes to the caller's outside energy), summed over the window's rectangle and kept
/// as one row a map row, trimmed to the columns some node reached.
///
/// A node's Gaussian exp(−q_xx x² − 2q_xy xy − q_yy y²) is a sum of outer products of a column and a row vector:
///
///   exp(−q_xx x²)·exp(−q_yy y²)·Σ_{m<M} (−2q_xy)^m x^m y^m / m!,
///
/// exact for a circular spot or an ellipse along the map's axes (M = 1). With ρ = |q_xy|/√(q_xx q_yy) (the oblique
/// footprint's skew: ≈ sin θ_x sin θ_y), the first omitted term is at most ρ^M·(M/e)^M/M! ≈ ρ^M/√(2πM) of the peak
/// (u = q_xx x², v = q_yy y²: |2q_xy xy| ≤ ρ(u + v) and max s^M e^{−s} = (M/e)^M); M is the least with that ≤ 4e-5,
/// which keeps the node within 1.2e-4 of its Gaussian (test_trapezoid_deposit.cpp: M = 1 at normal incidence or
/// along an axis, 3 at 10° on the diagonal, 5 at 30°). The 1-D Gaussians come in float lanes (lane_math.hpp's expf
/// every 8 blocks, second-order recurrences between); the window's pixels add the nodes' products in float, node
/// after node, 8 columns at a time on blocks aligned to the window's grid, in the same order on every thread and
/// vector width (AVX2 and default clones: the same bits). A node costs (2R/p)² × M products (1 225 × M at w = 35 µm,
/// 5 µm pixels) and no exponential a pixel; the map is touched once a window, not once a node.
class NodeDeposit
{
public:
  static constexpr std::size_t kWindowNodes = 64;       ///< most nodes in one window
  static constexpr double kWindowSpanPixels = 96.0;     ///< the nodes' centres span at most this (or a footprint)
  static constexpr double kMaxWindowRadiusPixels = 64;  ///< a node with a larger R is drawn alone
  static constexpr int kMaxRank = 24;                   ///< most outer products a node (enough for ρ ≤ 0.73)

  explicit NodeDeposit(const EnergyConfig& config);
  /// \brief The nodes of a window being filled: their count and the box of their centres.
  struct OpenWindow
  {
    std::size_t count = 0;
    Eigen::Vector2d lo = Eigen::Vector2d::Zero(), hi = Eigen::Vector2d::Zero();
    double major_radius_m = 0.0;  ///< the largest footprint's
    bool alone = false;           ///< its node is drawn alone (a footprint beyond kMaxWindowRadiusPixels)
  };
  /// \brief Whether \p node may join \p window (count > 0) on a map of pixel \p pixel_m; if not, the caller closes the
  /// window and starts a new one.
  bool joins(const OpenWindow& window, const QuadratureNode& node, double pixel_m) const;
  /// \brief Adds \p node to \p window (after joins() said yes, or to an empty window).
  void add(OpenWindow& window, const QuadratureNode& node, double pixel_m) const;
  /// \brief The weights of nodes[0 … count) on \p map's grid into \p out. Reads only the map's geometry: any number of
  /// threads may weigh at once, each into its own \p out. Added to the map with StrokeDeposit::apply.
  void weigh(const TiledEnergyMap& map, const QuadratureNode* nodes, std::size_t count, StrokeWeights& out) const;
  /// \brief Outer products M of a footprint (above).
  static int rank(const SpotFootprint& fp);

private:
  EnergyConfig config_;
};
}  // namespace scanhead
