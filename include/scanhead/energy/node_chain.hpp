/// \file node_chain.hpp
/// \brief The time integral along the spot's polyline as a weighted sum of Gaussians at its vertices (energy.method:
/// trapezoid): the nodes of the composite trapezoid rule, each shifted by the Euler–Maclaurin correction of the
/// polyline's kinks.
#pragma once

#include <Eigen/Core>
#include <cstdint>

#include "scanhead/energy/spot_footprint.hpp"

namespace scanhead
{
/// \brief One Gaussian of the sum: e_j·I(p − c_j)/P with the footprint of the sample it stands for.
struct QuadratureNode
{
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();  ///< c_j [m]
  double energy_j = 0.0;                             ///< e_j [J]
  SpotFootprint footprint;
};

/// \brief Turns the samples' segments into QuadratureNodes.
///
/// The energy of a chain of consecutive segments (sample k: from x_k to x_{k+1} in τ_k at power P_k, the path linear
/// between samples) is E(p) = Σ_k P_k ∫_0^{τ_k} G_k(p − x_k − (t/τ_k)Δ_k) dt, Δ_k = x_{k+1} − x_k, G = I/P the
/// normalised footprint. Each segment is cut into m_k = ⌈|Δ_k|/(w/2)⌉ equal panels (energy e = τP/m, step h = Δ/m);
/// on a panel the integrand f(t) is smooth, and the Euler–Maclaurin formula gives, in panel units,
///
///   ∫_0^N f = Σ_{j=0}^{N} f_j − (f_0 + f_N)/2 + Σ_k B_{2k}/(2k)!·(f^{(2k−1)}(0) − f^{(2k−1)}(N)).
///
/// Inside a chain the derivative terms of two neighbouring panels cancel but for the kink: vertex j between panels
/// l and r weighs W_j = (e_l + e_r)/2 and carries the dipole −∇G(p − x_j)·D_j, D_j = (e_r h_r − e_l h_l)/12, the
/// kink's (x_{j+1} − 2x_j + x_{j−1})·e/12: small, so the vertex is one Gaussian shifted by ε_j = D_j/W_j (the dipole
/// is the first-order Taylor term of W_j·G(p − x_j − ε_j)).
///
/// At a chain's ends the terms f′/12 − f‴/720 are large (the laser switches on or off; at h = w/3 a lone shift of the
/// end vertex would err by ~1e-3 of a track's peak) and are drawn by a five-point one-sided rule in steps of a third
/// of the end panel, Σ c_i f(i/3) = f′(0)/12 − f‴(0)/720 + O(f⁽⁵⁾), c = (−41/96, 53/80, −3/10, 17/240, −1/160) (the
/// Taylor moments solved; on the 1-D quadrature of a Gaussian track it errs by 2.7e-6 of the peak at h = 10 µm,
/// 3.4e-5 at 15 µm, 9e-5 at 17.5 µm = w/2, w = 35 µm): the end vertex weighs e·(1/2 − 41/96) and four nodes at a
/// third, two thirds, one and four thirds of the end panel into the chain, on that panel's straight line at its power
/// (the terms are those of the end panel's own integrand: a kink at its far vertex is that vertex's shift), carry
/// the rest; two of them are negative and the four sum to 0, so the energy is exact.
///
/// Errors, relative to the peak of a straight track (P/v)·I₀·w·√(π/2) at w the spot radius (minor), h ≤ w/2:
/// - straight constant-speed run: the aliasing of Gaussians h apart, 2·exp(−π²w²/(2h²)) ≤ 5.4e-9 (Poisson summation);
/// - a kink (velocity change δv between panels, ε = τδv/12): the shift's Taylor remainder W·εᵀHε/2, about
///   1.6·(h/w)·(ε/w)² ≤ 8e-5 for ε ≤ kMaxKinkShiftRadii·w; a sharper kink, a power step or a change of panel length
///   (ε ≈ h/12) ends the chain instead;
/// - a chain's end: ≤ 9e-5 (above).
/// A dwell (zero-length segment) is one node, its energy at its point, and ends the chain before it. The footprint of
/// a vertex is that of its right panel's sample (the chain's last vertex: its left's). Chains break where the laser
/// stops (flush), where a segment does not start where the previous ended, and at a vertex whose shift would exceed
/// kMaxKinkShiftRadii (a sharp corner, a power step). Every node depends only on the sequence of segments, so any
/// chunking of the stream gives the same nodes; the last segment stays pending until the next arrives or flush().
class NodeChain
{
public:
  static constexpr double kMaxPanelRadii = 0.5;  ///< panel length ≤ this many radii w (the footprint's minor)
  /// A vertex whose shift would exceed this many radii w ends the chain (a sharp corner, a power step): the end rules
  /// draw both sides instead (the shift's remainder would reach ~1.6·(h/w)·(ε/w)² ≈ 8e-5 of a track's peak).
  static constexpr double kMaxKinkShiftRadii = 0.01;
  static constexpr double kMaxEndPanelRadii = 0.03;  ///< on a chain's first and last segments

  /// \brief Adds the segment a → b of one sample (power P over τ, footprint fp). The nodes it completes are then taken
  /// one at a time with next() (memory stays bounded whatever a segment's length), all before the next add or flush.
  void add(const Eigen::Vector2d& a, const Eigen::Vector2d& b, double power_w, double period_s,
           const SpotFootprint& fp);
  /// \brief Ends the chain: its remaining nodes are then taken with next().
  void flush();
  /// \brief The next completed node, if any.
  bool next(QuadratureNode& node);
  void reset();

private:
  struct Panel
  {
    Eigen::Vector2d step = Eigen::Vector2d::Zero();  ///< h [m]
    double energy_j = 0.0;                           ///< e [J]
    SpotFootprint footprint;
  };
  struct Segment
  {
    Eigen::Vector2d start = Eigen::Vector2d::Zero(), end = Eigen::Vector2d::Zero();
    double energy_j = 0.0;  ///< τ·P
    SpotFootprint footprint;
    bool first = false;   ///< starts its chain
    double panels = 1.0;  ///< m
    Panel panel;          ///< each of its m panels
  };
  static constexpr int kEndNodes = 4;  ///< the end rule's nodes besides the end vertex
  /// \brief Whether \p s continues the pending segment's chain: it starts where that one ended, with a small kink.
  bool joins(const Segment& s) const;
  /// \brief Sets the panels of \p s (m and one panel: all alike).
  static void cut(Segment& s);
  /// \brief Queues the nodes of the pending segment: its start and inner vertices, with \p last also its end.
  void emitPending(bool last);
  /// \brief Queues the end rule's nodes at a third, two thirds, one and four thirds of the end panel \p end from the
  /// chain's end vertex \p from, along \p sign times its step (+1 from the start, −1 from the end).
  void queueEndRule(const Eigen::Vector2d& from, double sign, const Panel& end);
  /// \brief Vertex \p v (0 … m) of the segment being emitted.
  QuadratureNode vertex(std::int64_t v) const;
  bool pending_ = false;
  Segment segment_;  ///< the pending segment (its end vertex waits for the next segment)
  Panel left_;       ///< the panel before the pending segment's start (energy 0 at a chain's start)
  // The segment being emitted, the panel before it, whether it ends the chain, its next vertex; and the end rules'
  // nodes, given first.
  Segment emitted_;
  Panel emitted_left_;
  bool last_ = false;
  std::int64_t next_vertex_ = 0, vertices_ = 0;
  QuadratureNode extra_[2 * kEndNodes + 1];  ///< + a dwell's node
  int extras_ = 0, next_extra_ = 0;
};
}  // namespace scanhead
