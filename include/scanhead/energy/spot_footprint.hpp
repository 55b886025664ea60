/// \file spot_footprint.hpp
/// \brief The Gaussian spot on the work plane: stretched by oblique incidence, widened by defocus (SPEC §5).
#pragma once

#include <Eigen/Core>

#include "scanhead/energy/energy_config.hpp"

namespace scanhead
{
/// \brief Irradiance of the spot on the plane at offset r = p − c from its centre:
/// \f[ I(r) = \frac{2P\cos\theta}{\pi w^2}\,e^{-r^\top Q r}, \qquad
///     Q = \frac{2}{w^2}\left(I - d_{xy} d_{xy}^\top\right) \f]
/// with d the unit beam direction at the plane, d_xy its in-plane part (|d_xy| = sin θ) and w the
/// beam's 1/e² radius where it meets the plane. Along d_xy the footprint is w/cos θ wide, across it
/// w: a circular beam cut by an inclined plane (energy ∫I = P whatever θ). Defocus (Gaussian beam):
/// \f[ w(z) = w_0\sqrt{1 + (z/z_R)^2}, \qquad z_R = \pi w_0^2 / (M^2 \lambda) \f]
/// with z the distance from the waist along the beam (energy.defocus_mode, energy_config.hpp).
struct SpotFootprint
{
  double qxx = 0.0, qxy = 0.0, qyy = 0.0;  ///< Q [1/m²]: exponent −(qxx x² + 2 qxy x y + qyy y²)
  double radius_m = 0.0;                   ///< w across the plane of incidence [m] (the smaller semi-axis)
  double major_radius_m = 0.0;             ///< w / cos θ along it [m]
  double defocus_m = 0.0;                  ///< z used for w(z) [m]
};

/// \brief The footprint for a beam of unit direction \p direction (plane frame, pointing down).
/// \pre config validated; direction finite with |d_z| > 0 (a grazing beam never reaches the plane)
/// \throws NumericalError if the direction is not finite or runs parallel to the plane
SpotFootprint spotFootprint(const EnergyConfig& config, const Eigen::Vector3d& direction);

/// \brief spotFootprint with the configuration read once (the defocus mode, w0, z_R): the energy stage asks for a
/// footprint every sample (30 M on the THESIS layer). The same expressions, the same bits.
class SpotFootprintModel
{
public:
  /// \pre config validated
  explicit SpotFootprintModel(const EnergyConfig& config);
  /// \copydoc spotFootprint
  SpotFootprint operator()(const Eigen::Vector3d& direction) const;

private:
  enum class Defocus
  {
    kNone,
    kFixed,
    kField
  };
  Defocus defocus_mode_;
  double defocus_m_, focus_distance_m_;
  double w0_, rayleigh_m_;  ///< waist radius and z_R [m]
  bool oblique_incidence_;
};
}  // namespace scanhead
