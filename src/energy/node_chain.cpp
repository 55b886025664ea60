/// \file node_chain.cpp
/// \brief The trapezoid rule's nodes along the spot's polyline: kinks as shifts, chain ends by a five-point rule.
#include "scanhead/energy/node_chain.hpp"

#include <algorithm>
#include <cmath>

namespace scanhead
{
namespace
{
/// The end rule's weights c_1 … c_4 at i/3 of a panel (c_0 = −41/96 goes to the end vertex): node_chain.hpp.
constexpr double kEndVertexWeight = -41.0 / 96.0;
constexpr double kEndWeights[4] = {53.0 / 80.0, -3.0 / 10.0, 17.0 / 240.0, -1.0 / 160.0};
}  // namespace

void NodeChain::reset()
{
  pending_ = false;
  next_vertex_ = vertices_ = 0;
  extras_ = next_extra_ = 0;
}

void NodeChain::cut(Segment& s)
{
  // Finite and bounded: the sampled method's sub-step check on the segment came first (deposit_checks.hpp).
  s.panels = std::max(1.0, std::ceil((s.end - s.start).norm() / (kMaxPanelRadii * s.footprint.radius_m)));
  s.panel.step = (s.end - s.start) / s.panels;
  s.panel.energy_j = s.energy_j / s.panels;
  s.panel.footprint = s.footprint;
}

bool NodeChain::joins(const Segment& s) const
{
  if (!pending_ || s.start != segment_.end)
    return false;
  // The shift ε = D/W of the vertex between the pending segment's last panel and s's first (node_chain.hpp).
  const Panel &l = segment_.panel, &r = s.panel;
  const double weight = 0.5 * (l.energy_j + r.energy_j);
  const Eigen::Vector2d dipole = (r.energy_j * r.step - l.energy_j * l.step) / 12.0;
  return dipole.norm() <= kMaxKinkShiftRadii * std::min(s.footprint.radius_m, segment_.footprint.radius_m) * weight;
}

void NodeChain::add(const Eigen::Vector2d& a, const Eigen::Vector2d& b, double power_w, double period_s,
                    const SpotFootprint& fp)
{
  Segment s;
  s.start = a;
  s.end = b;
  s.energy_j = power_w * period_s;
  s.footprint = fp;
  cut(s);
  if (a == b)
  {
    // A dwell: exactly its energy at its point, and the chain before it ends there.
    flush();
    extra_[extras_++] = QuadratureNode{a, s.energy_j, fp};
    return;
  }
  const bool continues = joins(s);
  s.first = !continues;
  extras_ = next_extra_ = 0;
  if (pending_)
    emitPending(!continues);
  if (!continues)
    left_ = Panel();
  pending_ = true;
  segment_ = s;
}

void NodeChain::flush()
{
  extras_ = next_extra_ = 0;
  if (pending_)
    emitPending(true);
  pending_ = false;
}

void NodeChain::queueEndRule(const Eigen::Vector2d& from, double sign, const Panel& end)
{
  // Point i/3 of the end panel into the chain (i = 1 … 4) on the end panel's own straight line and at its power and
  // footprint: the Euler–Maclaurin terms are those of that panel's integrand (a kink at its other end is its vertex's
  // shift), and the weights sum to 0.
  for (int i = 1; i <= kEndNodes; ++i)
  {
    QuadratureNode& n = extra_[extras_++];
    n.centre = from + (sign * i / 3.0) * end.step;
    n.energy_j = kEndWeights[i - 1] * end.energy_j;
    n.footprint = end.footprint;
  }
}

void NodeChain::emitPending(bool last)
{
  emitted_ = segment_;
  emitted_left_ = left_;
  last_ = last;
  next_vertex_ = 0;
  vertices_ = static_cast<std::int64_t>(segment_.panels) + (last ? 1 : 0);
  if (segment_.first)
    queueEndRule(segment_.start, 1.0, segment_.panel);
  if (last)
    queueEndRule(segment_.end, -1.0, segment_.panel);
  left_ = segment_.panel;
}

QuadratureNode NodeChain::vertex(std::int64_t v) const
{
  const std::int64_t panels = static_cast<std::int64_t>(emitted_.panels);
  const Panel& h = emitted_.panel;
  const Panel& l = v == 0 ? emitted_left_ : h;
  const bool chain_start = v == 0 && emitted_.first, chain_end = v == panels && last_;
  const double e_left = chain_start ? 0.0 : l.energy_j, e_right = v == panels ? 0.0 : h.energy_j;
  QuadratureNode n;
  n.footprint = emitted_.footprint;
  n.centre = v == panels ? emitted_.end
                         : Eigen::Vector2d(emitted_.start + (static_cast<double>(v) / emitted_.panels) *
                                                                (emitted_.end - emitted_.start));
  if (chain_start || chain_end)
  {
    n.energy_j = (0.5 + kEndVertexWeight) * (chain_start ? e_right : e_left);  // the rest: the end rule's nodes
    return n;
  }
  n.energy_j = 0.5 * (e_left + e_right);
  n.centre += (e_right * h.step - e_left * l.step) / (12.0 * n.energy_j);
  return n;
}

bool NodeChain::next(QuadratureNode& node)
{
  if (next_extra_ < extras_)
  {
    node = extra_[next_extra_++];
    return true;
  }
  if (next_vertex_ >= vertices_)
    return false;
  node = vertex(next_vertex_++);
  return true;
}
}  // namespace scanhead
