/// \file recipe.cpp
/// \brief Marking recipes: presets, validation, and their application to a job (SPEC §2.5, §5).
#include "scanhead/job/recipe.hpp"

#include <cmath>

#include "scanhead/common/config_check.hpp"
#include "scanhead/common/errors.hpp"
#include "scanhead/job/generators/thesis_square_job.hpp"

namespace scanhead
{
namespace
{
constexpr const char* kPresetList = "job, custom, thesis1, thesis2, thesis3";

/// THESIS laser delays [s] (SPEC §2.5): the industrial tuning of recipe 1, and the values the THESIS
/// retuned with its simulator for the uniform-speed recipe 2 (§2.6.1: "les délais ... doivent être
/// réglés selon ce nouveau paramétrage", 341 µs and 53 µs). Recipe 3 (chapter 3) was retuned too but
/// its values are not printed: it keeps recipe 2's, since the delays make up for the galvos' time lag,
/// which does not depend on the speed.
constexpr double kThesisOnDelay1_s = 395e-6;
constexpr double kThesisOffDelay1_s = 107e-6;
constexpr double kThesisOnDelay23_s = 341e-6;
constexpr double kThesisOffDelay23_s = 53e-6;
constexpr double kThesisPower_w = 200.0;
constexpr const char* kMaxPowerText =
    "<= 1e+06 W (no continuous-wave laser reaches it; LPBF: 200 W - 1 kW)";  ///< thesis_square_job.hpp: 200 W on every
                                                                             ///< mark

/// 1, 2 or 3 for "thesis1".."thesis3", 0 otherwise.
int thesisNumber(const std::string& preset)
{
  if (preset == "thesis1")
    return 1;
  if (preset == "thesis2")
    return 2;
  if (preset == "thesis3")
    return 3;
  return 0;
}

[[noreturn]] void unknownPreset(const std::string& preset)
{
  throw ConfigError("recipe.preset must be one of " + std::string(kPresetList) + " (got '" + preset + "')");
}

bool isContourMark(const Polyline& line)
{
  return line.type == PolylineType::Mark && line.role == PolylineRole::Contour;
}
}  // namespace

void RecipeConfig::validate() const
{
  if (preset != "job" && preset != "custom" && thesisNumber(preset) == 0)
  {
    unknownPreset(preset);
  }
  // Every field is checked whatever the preset: a bad number in a config file is a mistake even
  // where the preset ignores it.
  requireSetting(contour_speed_mps > 0.0, "recipe.contour_speed_mps", "> 0", contour_speed_mps);
  requireSetting(hatch_speed_mps > 0.0, "recipe.hatch_speed_mps", "> 0", hatch_speed_mps);
  requireSetting(jump_speed_mps > 0.0, "recipe.jump_speed_mps", "> 0", jump_speed_mps);
  requireSetting(contour_jump_speed_mps > 0.0, "recipe.contour_jump_speed_mps", "> 0", contour_jump_speed_mps);
  requireSetting(contour_power_w >= 0.0, "recipe.contour_power_w", ">= 0", contour_power_w);
  requireSetting(hatch_power_w >= 0.0, "recipe.hatch_power_w", ">= 0", hatch_power_w);
  requireSetting(contour_power_w <= kMaxLaserPower_w, "recipe.contour_power_w", kMaxPowerText, contour_power_w);
  requireSetting(hatch_power_w <= kMaxLaserPower_w, "recipe.hatch_power_w", kMaxPowerText, hatch_power_w);
  requireSetting(std::isfinite(laser_on_delay_s), "recipe.laser_on_delay_s", "finite", laser_on_delay_s);
  requireSetting(std::isfinite(laser_off_delay_s), "recipe.laser_off_delay_s", "finite", laser_off_delay_s);
}

Recipe resolveRecipe(const RecipeConfig& config)
{
  Recipe r;
  const int thesis = thesisNumber(config.preset);
  if (thesis != 0)
  {
    const SquareRecipe speeds = thesisRecipe(thesis);  // the one source of the THESIS speeds
    r.override_job = true;
    r.contour_speed_mps = speeds.contour_mark_speed_mps;
    r.hatch_speed_mps = speeds.hatch_mark_speed_mps;
    r.jump_speed_mps = speeds.jump_speed_mps;
    r.contour_jump_speed_mps = speeds.contour_jump_speed_mps;
    r.contour_power_w = kThesisPower_w;
    r.hatch_power_w = kThesisPower_w;
    r.laser_on_delay_s = thesis == 1 ? kThesisOnDelay1_s : kThesisOnDelay23_s;
    r.laser_off_delay_s = thesis == 1 ? kThesisOffDelay1_s : kThesisOffDelay23_s;
    return r;
  }
  if (config.preset != "job" && config.preset != "custom")
  {
    unknownPreset(config.preset);
  }
  r.override_job = (config.preset == "custom");
  r.contour_speed_mps = config.contour_speed_mps;
  r.contour_power_w = config.contour_power_w;
  r.hatch_speed_mps = config.hatch_speed_mps;
  r.hatch_power_w = config.hatch_power_w;
  r.jump_speed_mps = config.jump_speed_mps;
  r.contour_jump_speed_mps = config.contour_jump_speed_mps;
  r.laser_on_delay_s = config.laser_on_delay_s;
  r.laser_off_delay_s = config.laser_off_delay_s;
  return r;
}

Job applyRecipe(const Job& job, const Recipe& recipe)
{
  Job out = job;
  if (!recipe.override_job)
  {
    return out;
  }
  for (std::size_t p = 0; p < out.polylines.size(); ++p)
  {
    Polyline& line = out.polylines[p];
    if (line.type == PolylineType::Mark)
    {
      const bool contour = line.role == PolylineRole::Contour;
      line.power_w = contour ? recipe.contour_power_w : recipe.hatch_power_w;
      if (line.dwell_s <= 0.0)  // a dwell keeps its time; its speed is not used
      {
        line.speed_mps = contour ? recipe.contour_speed_mps : recipe.hatch_speed_mps;
      }
      continue;
    }
    // A jump between two contour marks: its immediate neighbours in the job, both MARK Contour.
    const bool contour_jump = p > 0 && p + 1 < out.polylines.size() && isContourMark(job.polylines[p - 1]) &&
                              isContourMark(job.polylines[p + 1]);
    line.speed_mps = contour_jump ? recipe.contour_jump_speed_mps : recipe.jump_speed_mps;
  }
  return out;
}
}  // namespace scanhead
