/// \file test_trapezoid_deposit.cpp
/// \brief energy.method trapezoid: the nodes of node_chain.hpp against exact integrals of polynomials along the path,
/// and the separable sums of node_deposit.hpp against the Gaussian they expand. (The maps against the closed form,
/// the line source and the sampled method: test_stroke_deposit.cpp, for both methods.)
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "scanhead/energy/energy_config.hpp"
#include "scanhead/energy/node_chain.hpp"
#include "scanhead/energy/node_deposit.hpp"
#include "scanhead/energy/spot_footprint.hpp"
#include "scanhead/energy/stroke_deposit.hpp"
#include "scanhead/energy/tiled_energy_map.hpp"

using scanhead::EnergyConfig;
using scanhead::NodeChain;
using scanhead::NodeDeposit;
using scanhead::QuadratureNode;
using scanhead::SpotFootprint;

namespace
{
constexpr double kTs = 1e-5;  // 100 kHz

struct Sample
{
  Eigen::Vector2d x;
  double power_w;
};

/// \brief The nodes of the samples' segments (sample k → k+1 at sample k's power; a zero power ends the chain), as
/// the accumulator feeds them.
std::vector<QuadratureNode> nodesOf(const std::vector<Sample>& samples, const SpotFootprint& fp)
{
  NodeChain chain;
  std::vector<QuadratureNode> nodes;
  QuadratureNode n;
  for (std::size_t k = 0; k + 1 < samples.size(); ++k)
  {
    if (samples[k].power_w > 0.0)
      chain.add(samples[k].x, samples[k + 1].x, samples[k].power_w, kTs, fp);
    else
      chain.flush();
    while (chain.next(n))
      nodes.push_back(n);
  }
  chain.flush();
  while (chain.next(n))
    nodes.push_back(n);
  return nodes;
}

/// \brief ∫ P(t)·f(x(t)) dt along the polyline by Gauss–Legendre with 5 nodes a segment (exact for degree ≤ 9).
template <class F>
double pathIntegral(const std::vector<Sample>& samples, F f)
{
  const double u[5] = {-0.9061798459386640, -0.5384693101056831, 0.0, 0.5384693101056831, 0.9061798459386640};
  const double w[5] = {0.2369268850561891, 0.4786286704993665, 0.5688888888888889, 0.4786286704993665,
                       0.2369268850561891};
  double total = 0.0;
  for (std::size_t k = 0; k + 1 < samples.size(); ++k)
    for (int i = 0; i < 5; ++i)
    {
      const double s = 0.5 * (1.0 + u[i]);
      total += samples[k].power_w * kTs * 0.5 * w[i] * f(samples[k].x + s * (samples[k + 1].x - samples[k].x));
    }
  return total;
}

SpotFootprint circular()
{
  return scanhead::spotFootprint(EnergyConfig(), Eigen::Vector3d(0, 0, -1));
}
}  // namespace

// On straight chains at constant speed and power the nodes integrate every polynomial of degree ≤ 4 along the path
// exactly (the trapezoid rule with the Euler–Maclaurin terms f′/12 and f‴/720 at the ends, drawn by the five-point
// rule): chains of 1, 2, 3 and 40 segments, slow (one panel a segment) and fast (several), with a power step and a
// dwell (each closes its chain), in 2-D along a slanted line.
TEST(NodeChain, PolynomialsOfDegreeFourAreExactOnStraightChains)
{
  const SpotFootprint fp = circular();
  const Eigen::Vector2d dir = Eigen::Vector2d(0.8, 0.6);
  for (const double speed : {0.3, 1.5, 4.0})  // 3, 15 and 40 µm a sample: 1, 1 and 3 panels (w/2 = 17.5 µm)
    for (const int segments : {1, 2, 3, 40})
    {
      std::vector<Sample> s;
      for (int k = 0; k <= segments; ++k)
        s.push_back({Eigen::Vector2d(1e-3, 2e-3) + k * speed * kTs * dir, 150.0});
      s.back().power_w = 0.0;  // the laser stops at the last sample
      const std::vector<QuadratureNode> nodes = nodesOf(s, fp);
      for (int degree = 0; degree <= 4; ++degree)
      {
        // f = (a·x − c)^degree in metres scaled to order 1 over the chain.
        const double scale = 1.0 / (segments * speed * kTs + 1e-12);
        auto f = [&](const Eigen::Vector2d& x) {
          return std::pow((dir.dot(x - Eigen::Vector2d(1e-3, 2e-3)) * scale - 0.3), degree);
        };
        double sum = 0.0;
        for (const QuadratureNode& n : nodes)
          sum += n.energy_j * f(n.centre);
        const double exact = pathIntegral(s, f);
        EXPECT_NEAR(sum, exact, 1e-12 * 150.0 * kTs * segments)
            << "speed " << speed << ", " << segments << " segments, degree " << degree;
      }
    }
}

// Energy and centroid are exact on any chain: kinks (a random walk), power steps, dwells, laser off and on. The
// trapezoid rule is exact for a linear f on every panel, the kinks' dipoles telescope, and the end rules (exact for
// polynomials of degree 4 on the end panel's line) sum to 0 and give its f′/12.
TEST(NodeChain, EnergyAndCentroidAreExactOnAnyPath)
{
  std::mt19937 rng(20261204);  // fixed seed
  std::uniform_real_distribution<double> turn(-0.3, 0.3);
  const SpotFootprint fp = circular();
  std::vector<Sample> s;
  Eigen::Vector2d x(1e-3, 1e-3);
  double heading = 0.0;
  for (int k = 0; k < 3000; ++k)
  {
    heading += turn(rng);
    const double speed = k % 700 < 50 ? 0.0 : 0.5 + 1.5 * ((k / 97) % 3);  // dwells, three speeds
    x += speed * kTs * Eigen::Vector2d(std::cos(heading), std::sin(heading));
    const double power = k % 500 > 460 ? 0.0 : 100.0 + 20.0 * ((k / 130) % 3);  // laser off, power steps
    s.push_back({x, power});
  }
  const std::vector<QuadratureNode> nodes = nodesOf(s, fp);
  double energy = 0.0;
  Eigen::Vector2d moment = Eigen::Vector2d::Zero();
  for (const QuadratureNode& n : nodes)
  {
    energy += n.energy_j;
    moment += n.energy_j * n.centre;
  }
  const double exact_energy = pathIntegral(s, [](const Eigen::Vector2d&) { return 1.0; });
  const double mx = pathIntegral(s, [](const Eigen::Vector2d& p) { return p.x(); });
  const double my = pathIntegral(s, [](const Eigen::Vector2d& p) { return p.y(); });
  EXPECT_NEAR(energy, exact_energy, 1e-12 * exact_energy);
  EXPECT_NEAR(moment.x() / energy, mx / exact_energy, 1e-15);  // [m]: 1 fm
  EXPECT_NEAR(moment.y() / energy, my / exact_energy, 1e-15);
  EXPECT_GT(nodes.size(), s.size() / 2);
}

// A node's separable outer products equal its Gaussian exp(−rᵀQr), normalised, at every pixel centre: within 1.2e-4
// of the peak (the expansion's first omitted term ≤ 4e-5, the rest of the series and the normalisation ~2× that)
// plus float rounding, for footprints from circular to 30° of incidence on the diagonal (skew ρ up to 0.14).
TEST(NodeDeposit, OuterProductsAreTheGaussian)
{
  EnergyConfig cfg;
  const double p = cfg.pixel_m;
  const scanhead::TiledEnergyMap map(Eigen::Vector2d(0, 0), Eigen::Vector2d(1e-3, 1e-3), p, 1u << 24);
  NodeDeposit deposit(cfg);
  for (const double incidence_deg : {0.0, 10.0, 20.0, 30.0})
    for (const double azimuth_deg : {0.0, 45.0, 120.0})
    {
      const double t = incidence_deg * M_PI / 180.0, a = azimuth_deg * M_PI / 180.0;
      const Eigen::Vector3d d(std::sin(t) * std::cos(a), std::sin(t) * std::sin(a), -std::cos(t));
      QuadratureNode node;
      node.footprint = scanhead::spotFootprint(cfg, d);
      node.centre = Eigen::Vector2d(0.5e-3 + 0.37 * p, 0.5e-3 - 0.21 * p);
      node.energy_j = 1e-3;
      scanhead::StrokeWeights w;
      deposit.weigh(map, &node, 1, w);
      // The Gaussian on the same pixels (the node's square), normalised to the same total.
      const SpotFootprint& q = node.footprint;
      double reference_total = 0.0, drawn_total = 0.0;
      std::vector<double> reference;
      for (const scanhead::StrokeWeights::Row& r : w.rows)
        for (int i = 0; i < r.n; ++i)
        {
          const double x = (static_cast<double>(r.col + i) + 0.5) * p - node.centre.x();
          const double y = (static_cast<double>(r.row) + 0.5) * p - node.centre.y();
          reference.push_back(std::exp(-(q.qxx * x * x + 2.0 * q.qxy * x * y + q.qyy * y * y)));
          reference_total += reference.back();
          drawn_total += w.weights[r.offset + static_cast<std::size_t>(i)];
        }
      double worst = 0.0, peak = 0.0;
      std::size_t k = 0;
      for (const scanhead::StrokeWeights::Row& r : w.rows)
        for (int i = 0; i < r.n; ++i, ++k)
        {
          const double ref = reference[k] / reference_total,
                       got = w.weights[r.offset + static_cast<std::size_t>(i)] / drawn_total;
          worst = std::max(worst, std::abs(got - ref));
          peak = std::max(peak, ref);
        }
      const double rho = std::abs(q.qxy) / std::sqrt(q.qxx * q.qyy);
      std::cout << "[node] incidence " << incidence_deg << "°, azimuth " << azimuth_deg << "°: skew " << rho << ", "
                << NodeDeposit::rank(q) << " products, worst " << worst / peak << " of the peak\n";
      EXPECT_LT(worst / peak, 1.2e-4) << incidence_deg << "° " << azimuth_deg << "°";
      EXPECT_NEAR(drawn_total, node.energy_j, 1e-6 * node.energy_j);
    }
}

// A window of two nodes, the second a few pixels to the right of the first: its square then starts at another column
// of an 8-column block and takes 5, 6 or 7 blocks (the kernels unrolled for 5 and 6 blocks and the loop over any
// count), at ranks 1 to 5. Each pixel equals the sum of the two nodes' Gaussians, each normalised over its own square
// to its energy, within 1.2e-4 of the peak (as above); the energy is the two nodes'.
TEST(NodeDeposit, WindowOfTwoNodesIsTheSumOfTheirGaussians)
{
  EnergyConfig cfg;
  const double p = cfg.pixel_m;
  const scanhead::TiledEnergyMap map(Eigen::Vector2d(0, 0), Eigen::Vector2d(1e-3, 1e-3), p, 1u << 24);
  NodeDeposit deposit(cfg);
  for (const double incidence_deg : {0.0, 10.0, 30.0})
    for (const double shift_pixels : {3.0, 6.0, 7.0})
    {
      const double t = incidence_deg * M_PI / 180.0, a = M_PI / 4.0;
      const Eigen::Vector3d d(std::sin(t) * std::cos(a), std::sin(t) * std::sin(a), -std::cos(t));
      QuadratureNode nodes[2];
      for (int k = 0; k < 2; ++k)
      {
        nodes[k].footprint = scanhead::spotFootprint(cfg, d);
        nodes[k].centre = Eigen::Vector2d(0.5e-3 + (0.37 + k * shift_pixels) * p, 0.5e-3 - (0.21 + 1.3 * k) * p);
        nodes[k].energy_j = k == 0 ? 1e-3 : 0.6e-3;
      }
      scanhead::StrokeWeights w;
      deposit.weigh(map, nodes, 2, w);
      // Each node's Gaussian on its own square of half-side R (pixel centres within R along each axis), normalised.
      const SpotFootprint& q = nodes[0].footprint;
      const double radius = cfg.truncation_radii * q.major_radius_m;
      auto gaussian = [&](const QuadratureNode& n, std::int64_t col, std::int64_t row) {
        const double x = (static_cast<double>(col) + 0.5) * p - n.centre.x();
        const double y = (static_cast<double>(row) + 0.5) * p - n.centre.y();
        if (std::abs(x) > radius || std::abs(y) > radius)
          return 0.0;
        return std::exp(-(q.qxx * x * x + 2.0 * q.qxy * x * y + q.qyy * y * y));
      };
      double norm[2] = {0.0, 0.0};
      for (int k = 0; k < 2; ++k)
        for (std::int64_t row = 0; row < 200; ++row)
          for (std::int64_t col = 0; col < 200; ++col)
            norm[k] += gaussian(nodes[k], col, row);
      double worst = 0.0, peak = 0.0, drawn_total = 0.0;
      for (const scanhead::StrokeWeights::Row& r : w.rows)
        for (int i = 0; i < r.n; ++i)
        {
          double ref = 0.0;
          for (int k = 0; k < 2; ++k)
            ref += nodes[k].energy_j * gaussian(nodes[k], r.col + i, r.row) / norm[k];
          const double got = w.weights[r.offset + static_cast<std::size_t>(i)] / w.total * 1.6e-3;
          worst = std::max(worst, std::abs(got - ref));
          peak = std::max(peak, ref);
          drawn_total += w.weights[r.offset + static_cast<std::size_t>(i)];
        }
      int widest = 0;
      for (const scanhead::StrokeWeights::Row& r : w.rows)
        widest = std::max(widest, r.n);
      std::cout << "[window] incidence " << incidence_deg << "°, second node " << shift_pixels
                << " px on: " << NodeDeposit::rank(q) << " products, widest row " << widest << " px, worst "
                << worst / peak << " of the peak\n";
      EXPECT_LT(worst / peak, 1.2e-4) << incidence_deg << "°, shift " << shift_pixels;
      EXPECT_NEAR(drawn_total, 1.6e-3, 1e-6 * 1.6e-3);
      EXPECT_NEAR(w.total, drawn_total, 1e-6 * drawn_total);  // (the rows are summed in float lanes)
    }
}
