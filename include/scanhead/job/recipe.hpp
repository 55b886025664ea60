/// \file recipe.hpp
/// \brief Marking recipes: speed and power per polyline role, laser on/off delays (SPEC §2.5, §5).
#pragma once

#include <string>

#include "scanhead/job/scan_job.hpp"

namespace scanhead
{
/// \brief Above this a laser power is impossible [W]: the largest continuous-wave industrial
/// lasers are multi-kW fibre lasers of the 100 kW class (IPG YLS series); LPBF lasers give
/// 200 W–1 kW (EOS M 290: 400 W; SLM 280: up to 1 kW). A power is checked against it wherever it
/// is set (recipe, cam, job polylines: run_plan.hpp).
constexpr double kMaxLaserPower_w = 1.0e6;
/// \brief Above this a power is possible but not LPBF's (warning, run_plan.hpp) [W].
constexpr double kLpbfLaserPower_w = 1.0e3;

/// \brief A recipe as the machine operator sets it.
///
/// preset "job": the job's own speeds and powers, only the laser delays below apply;
/// "custom": every field below; "thesis1" | "thesis2" | "thesis3": the THESIS recipes (SPEC §5,
/// THESIS §2.5.1 and §2.6: speeds, 200 W on marks, laser delays 395/107 µs for recipes 1 and 2
/// (the industrial tuning), 341/53 µs for recipe 3 (retuned for the faster recipe)); the fields
/// are then ignored.
struct RecipeConfig
{
  std::string preset = "job";
  double contour_speed_mps = 1.5;       ///< MARK polylines with role Contour [m/s]
  double contour_power_w = 200.0;       ///< [W]
  double hatch_speed_mps = 1.0;         ///< MARK polylines with role Hatch or Unspecified [m/s]
  double hatch_power_w = 200.0;         ///< [W]
  double jump_speed_mps = 6.0;          ///< JUMP polylines [m/s]
  double contour_jump_speed_mps = 4.5;  ///< a jump from a contour to a contour [m/s]
  /// Laser-on delay: the laser comes on this long after the NC starts a mark (jump→mark), counted
  /// on the command timeline X_inter [s]. Default (T1 + T2)/2: the laser follows Q_filt2.
  double laser_on_delay_s = 192.5e-6;
  /// Laser-off delay: the laser goes off this long after the NC ends a mark [s].
  double laser_off_delay_s = 192.5e-6;

  /// \throws ConfigError naming recipe.<field> and the value (unknown preset: lists the known ones)
  void validate() const;
};

/// \brief The recipe in force: the preset's values, or the fields for "custom" and "job".
struct Recipe
{
  bool override_job = false;  ///< false for "job": speeds and powers stay the job's
  double contour_speed_mps = 1.5;
  double contour_power_w = 200.0;
  double hatch_speed_mps = 1.0;
  double hatch_power_w = 200.0;
  double jump_speed_mps = 6.0;
  double contour_jump_speed_mps = 4.5;
  double laser_on_delay_s = 192.5e-6;
  double laser_off_delay_s = 192.5e-6;
};

/// \brief Resolves a (validated) RecipeConfig. \throws ConfigError on an unknown preset
Recipe resolveRecipe(const RecipeConfig& config);

/// \brief A copy of \p job with the recipe's speeds and powers (unchanged if !override_job).
///
/// MARK Contour → contour speed/power; MARK Hatch/Unspecified → hatch speed/power (dwells keep
/// their time, take the power); JUMP → jump speed, or contour_jump speed when the previous and
/// next polylines are both contour marks.
Job applyRecipe(const Job& job, const Recipe& recipe);
}  // namespace scanhead
