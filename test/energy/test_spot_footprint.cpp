/// \file test_spot_footprint.cpp
/// \brief Oblique and defocused spots: energy conserved, aspect ratio 1/cos θ, w(z) of a Gaussian beam.
#include <gtest/gtest.h>

#include <cmath>

#include "fixtures/optics_fixture.hpp"
#include "scanhead/common/errors.hpp"
#include "scanhead/energy/energy_accumulator.hpp"
#include "scanhead/optics/optical_model.hpp"

using scanhead::EnergyAccumulator;
using scanhead::EnergyConfig;
using scanhead::EnergyMap;
using scanhead::SpotChunk;
using scanhead::SpotSample;

namespace
{
constexpr double kTs = 1e-5;

struct Moments
{
  double energy = 0.0;
  double major = 0.0, minor = 0.0;  ///< standard deviations along the principal axes [m]
  double major_angle = 0.0;         ///< direction of the major axis [rad]
};

/// Energy and principal second moments of a map (an independent check of the footprint's shape).
Moments moments(const EnergyMap& map)
{
  double s = 0, sx = 0, sy = 0;
  for (int r = 0; r < map.height(); ++r)
    for (int c = 0; c < map.width(); ++c)
    {
      const double e = map.at(c, r);
      s += e;
      sx += e * (c + 0.5);
      sy += e * (r + 0.5);
    }
  const double mx = sx / s, my = sy / s;
  double cxx = 0, cxy = 0, cyy = 0;
  for (int r = 0; r < map.height(); ++r)
    for (int c = 0; c < map.width(); ++c)
    {
      const double e = map.at(c, r), dx = c + 0.5 - mx, dy = r + 0.5 - my;
      cxx += e * dx * dx;
      cxy += e * dx * dy;
      cyy += e * dy * dy;
    }
  cxx /= s;
  cxy /= s;
  cyy /= s;
  const double mean = 0.5 * (cxx + cyy), diff = std::sqrt(0.25 * (cxx - cyy) * (cxx - cyy) + cxy * cxy);
  Moments m;
  m.energy = s * map.pixel() * map.pixel();
  m.major = std::sqrt(mean + diff) * map.pixel();
  m.minor = std::sqrt(mean - diff) * map.pixel();
  m.major_angle = 0.5 * std::atan2(2 * cxy, cxx - cyy);
  return m;
}

/// A 1 ms dwell of 100 W at the origin with the given beam direction.
EnergyMap dwell(const EnergyConfig& cfg, const Eigen::Vector3d& direction, double half_size_m = 0.4e-3)
{
  EnergyAccumulator acc(cfg, Eigen::Vector2d::Constant(-half_size_m), Eigen::Vector2d::Constant(half_size_m));
  SpotChunk c;
  c.period_s = kTs;
  SpotSample s;
  s.direction = direction;
  s.power_w = 100.0;
  c.samples.assign(100, s);
  acc.process(c);
  acc.finish();
  EXPECT_EQ(acc.energyOutsideMap(), 0.0);
  return acc.map().toDense();
}
}  // namespace

// Issue acceptance: at the field edge the footprint's aspect ratio is 1/cos(incidence) within 1 %,
// along the beam's plane of incidence, and the energy is conserved within 0.5 % (normal and oblique).
TEST(SpotFootprint, ObliqueAtTheFieldEdge)
{
  const scanhead::OpticalModel optics(scanhead::test_support::nominalGeometry(), scanhead::OpticsConfig());
  const Eigen::Vector2d corner(0.17, 0.17);  // field corner (half width 0.175 m)
  const scanhead::OpticalModel::Ray ray = optics.trace(optics.inverse(corner));
  ASSERT_NEAR((ray.spot - corner).norm(), 0.0, 1e-9);
  const double cos_theta = std::abs(ray.direction.z());
  EXPECT_LT(cos_theta, 0.97) << "the field corner should be clearly oblique";
  EnergyConfig cfg;
  cfg.pixel_m = 2e-6;
  const double energy = 100.0 * kTs * 100;
  const Moments normal = moments(dwell(cfg, Eigen::Vector3d(0, 0, -1)));
  const Moments oblique = moments(dwell(cfg, ray.direction));
  EXPECT_NEAR(normal.energy, energy, 5e-3 * energy);
  EXPECT_NEAR(oblique.energy, energy, 5e-3 * energy);
  EXPECT_NEAR(normal.major / normal.minor, 1.0, 1e-3);
  const double aspect = oblique.major / oblique.minor;
  EXPECT_NEAR(aspect * cos_theta, 1.0, 0.01) << "aspect " << aspect << " vs 1/cos " << 1.0 / cos_theta;
  // The minor axis keeps the beam's w/2 standard deviation; the major axis lies along d_xy.
  EXPECT_NEAR(oblique.minor, 0.5 * 35e-6, 0.01 * 0.5 * 35e-6);
  const double along = std::atan2(ray.direction.y(), ray.direction.x());
  EXPECT_NEAR(std::abs(std::sin(oblique.major_angle - along)), 0.0, 0.01);
  std::cout << "field corner: cos(incidence) " << cos_theta << ", aspect " << aspect << " (1/cos " << 1.0 / cos_theta
            << "), energy error " << (oblique.energy - energy) / energy << "\n";
}

// Without oblique_incidence the footprint stays circular whatever the direction.
TEST(SpotFootprint, ObliqueCanBeSwitchedOff)
{
  EnergyConfig cfg;
  cfg.oblique_incidence = false;
  const Moments m = moments(dwell(cfg, Eigen::Vector3d(0.2, 0.1, -0.97).normalized()));
  EXPECT_NEAR(m.major / m.minor, 1.0, 1e-3);
}

// Defocus: w(z) = w0·sqrt(1 + (z/zR)²), zR = π w0²/(M² λ); energy conserved.
TEST(SpotFootprint, DefocusWidensTheSpotAsAGaussianBeam)
{
  EnergyConfig cfg;
  cfg.defocus_mode = "fixed";
  cfg.defocus_m = 2.0 * cfg.rayleighLength();  // w = w0·√5
  const double w = 35e-6 * std::sqrt(5.0);
  const Moments m = moments(dwell(cfg, Eigen::Vector3d(0, 0, -1), 0.6e-3));
  EXPECT_NEAR(m.minor, 0.5 * w, 0.01 * 0.5 * w);
  EXPECT_NEAR(m.major, 0.5 * w, 0.01 * 0.5 * w);
  EXPECT_NEAR(m.energy, 1e-1, 5e-3 * 1e-1);
  EXPECT_NEAR(cfg.rayleighLength(), M_PI * 35e-6 * 35e-6 / (1.1 * 1.07e-6), 1e-12);
  // "field": a static focus on a sphere: z = L (1/cos θ − 1).
  cfg.defocus_mode = "field";
  cfg.defocus_m = 0.0;
  const Eigen::Vector3d d = Eigen::Vector3d(0.1, 0.0, -1.0).normalized();
  const scanhead::SpotFootprint fp = scanhead::spotFootprint(cfg, d);
  EXPECT_NEAR(fp.defocus_m, 0.7 * (std::sqrt(1.01) - 1.0), 1e-12);
  const double zr = cfg.rayleighLength();
  EXPECT_NEAR(fp.radius_m, 35e-6 * std::sqrt(1.0 + fp.defocus_m * fp.defocus_m / (zr * zr)), 1e-15);
}

TEST(SpotFootprint, BadSettingsAndDirectionsAreNamed)
{
  EnergyConfig cfg;
  cfg.defocus_mode = "sphere";
  EXPECT_THROW(cfg.validate(), scanhead::ConfigError);
  cfg = EnergyConfig();
  cfg.beam_quality_m2 = 0.5;
  EXPECT_THROW(cfg.validate(), scanhead::ConfigError);
  EXPECT_THROW(scanhead::spotFootprint(EnergyConfig(), Eigen::Vector3d(1, 0, 0)), scanhead::NumericalError);
  EXPECT_THROW(scanhead::spotFootprint(EnergyConfig(), Eigen::Vector3d(NAN, 0, -1)), scanhead::NumericalError);
}
