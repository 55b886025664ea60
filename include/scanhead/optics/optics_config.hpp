/// \file optics_config.hpp
/// \brief Parameters of the optical chain that the URDF does not carry (materials, field, solver).
#pragma once

#include <string>

namespace scanhead
{
struct OpticsConfig
{
  std::string urdf_path =
      "urdf/scanhead.urdf";  ///< the NOMINAL head; relative paths resolve against the package share dir
  /// The machine's assembly defects (defect_set_spec.hpp): nominal | opt_table2 |
  /// random:seed=N[,mm=B][,mrad=B] | a defect set file. A set replaces the origins of the URDF's
  /// defect joints; nominal keeps the URDF as it is. The graph reads the defective URDF from
  /// robot_description (launch arg defects:=, which sets this key too).
  std::string defects = "nominal";
  double window_thickness_m = 3.0e-3;  ///< e_v, both protective windows [m]
  double n_gas = 1.00028;              ///< n1, refractive index of the process gas (argon, 1064 nm)
  double n_window = 1.4496;            ///< n2, fused silica at 1064 nm
  double field_half_width_m = 0.175;   ///< the job must stay inside |x|,|y| <= this [m]
  double newton_tolerance_m = 1e-12;   ///< Newton inverse stops when the spot error is below this [m]
  int newton_max_iterations = 30;

  /// \throws ConfigError naming the field and value
  void validate() const;
};
}  // namespace scanhead
