/// \file test_recipe.cpp
/// \brief Marking recipes (SPEC §2.5, §5): presets, validation, application to a job.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

#include "fixtures/polyline_fixture.hpp"
#include "scanhead/common/errors.hpp"
#include "scanhead/job/recipe.hpp"

using scanhead::ConfigError;
using scanhead::Job;
using scanhead::PolylineRole;
using scanhead::PolylineType;
using scanhead::Recipe;
using scanhead::RecipeConfig;

namespace
{
using scanhead::test_support::line;

/// The ConfigError message of validate(), or "" if it passes.
std::string validationMessage(const RecipeConfig& config)
{
  try
  {
    config.validate();
  }
  catch (const ConfigError& e)
  {
    return e.what();
  }
  return "";
}

scanhead::Polyline mark(PolylineRole role, std::vector<Eigen::Vector2d> points)
{
  scanhead::Polyline p = line(PolylineType::Mark, 0.8, 50.0, std::move(points));
  p.role = role;
  return p;
}

scanhead::Polyline jump(std::vector<Eigen::Vector2d> points)
{
  return line(PolylineType::Jump, 3.0, 0.0, std::move(points));
}
}  // namespace

// THESIS recipes (SPEC §5, THESIS §2.6): speeds as thesisRecipe, 200 W, delays 395/107 µs for
// recipe 1 and 341/53 µs (retuned for the uniform speeds, §2.6.1) for recipes 2 and 3.
// Exact: the values are copied, never computed.
TEST(Recipe, ThesisPresets)
{
  struct Expected
  {
    const char* preset;
    double contour, hatch, contour_jump, jump, on, off;
  };
  const Expected cases[] = {
      {"thesis1", 1.5, 1.0, 4.5, 6.0, 395e-6, 107e-6},
      {"thesis2", 1.5, 1.5, 6.0, 6.0, 341e-6, 53e-6},
      {"thesis3", 3.0, 3.0, 12.0, 12.0, 341e-6, 53e-6},
  };
  for (const Expected& e : cases)
  {
    RecipeConfig config;
    config.preset = e.preset;
    config.contour_speed_mps = 9.0;  // ignored by a preset
    config.laser_on_delay_s = 1.0;
    ASSERT_NO_THROW(config.validate());
    const Recipe r = scanhead::resolveRecipe(config);
    EXPECT_TRUE(r.override_job) << e.preset;
    EXPECT_EQ(r.contour_speed_mps, e.contour) << e.preset;
    EXPECT_EQ(r.hatch_speed_mps, e.hatch) << e.preset;
    EXPECT_EQ(r.contour_jump_speed_mps, e.contour_jump) << e.preset;
    EXPECT_EQ(r.jump_speed_mps, e.jump) << e.preset;
    EXPECT_EQ(r.contour_power_w, 200.0) << e.preset;
    EXPECT_EQ(r.hatch_power_w, 200.0) << e.preset;
    EXPECT_EQ(r.laser_on_delay_s, e.on) << e.preset;
    EXPECT_EQ(r.laser_off_delay_s, e.off) << e.preset;
  }
}

// "job": only the delays apply; "custom": every field.
TEST(Recipe, JobAndCustomPresets)
{
  RecipeConfig config;
  config.contour_speed_mps = 2.5;
  config.hatch_power_w = 170.0;
  config.laser_on_delay_s = -20e-6;  // negative: the laser comes on before the mark starts
  config.laser_off_delay_s = 80e-6;
  const Recipe job = scanhead::resolveRecipe(config);
  EXPECT_FALSE(job.override_job);
  EXPECT_EQ(job.laser_on_delay_s, -20e-6);
  EXPECT_EQ(job.laser_off_delay_s, 80e-6);
  config.preset = "custom";
  const Recipe custom = scanhead::resolveRecipe(config);
  EXPECT_TRUE(custom.override_job);
  EXPECT_EQ(custom.contour_speed_mps, 2.5);
  EXPECT_EQ(custom.hatch_power_w, 170.0);
  EXPECT_EQ(custom.hatch_speed_mps, 1.0);
  EXPECT_EQ(custom.jump_speed_mps, 6.0);
  EXPECT_EQ(custom.contour_jump_speed_mps, 4.5);
  EXPECT_EQ(custom.laser_on_delay_s, -20e-6);
  config.preset = "thesis4";
  EXPECT_THROW(scanhead::resolveRecipe(config), ConfigError);
}

// Messages name recipe.<field> and the value; an unknown preset lists the known ones.
TEST(Recipe, ValidationMessages)
{
  EXPECT_EQ(validationMessage(RecipeConfig()), "");
  RecipeConfig c;
  c.preset = "fast";
  EXPECT_EQ(validationMessage(c), "recipe.preset must be one of job, custom, thesis1, thesis2, thesis3 (got 'fast')");
  c = RecipeConfig();
  c.contour_speed_mps = 0.0;
  EXPECT_EQ(validationMessage(c), "recipe.contour_speed_mps must be > 0 (got 0)");
  c = RecipeConfig();
  c.hatch_speed_mps = std::numeric_limits<double>::infinity();
  EXPECT_EQ(validationMessage(c), "recipe.hatch_speed_mps must be finite (got inf)");
  c = RecipeConfig();
  c.jump_speed_mps = -6.0;
  EXPECT_EQ(validationMessage(c), "recipe.jump_speed_mps must be > 0 (got -6)");
  c = RecipeConfig();
  c.contour_jump_speed_mps = std::nan("");
  EXPECT_EQ(validationMessage(c), "recipe.contour_jump_speed_mps must be > 0 (got nan)");
  c = RecipeConfig();
  c.contour_power_w = -1.0;
  EXPECT_EQ(validationMessage(c), "recipe.contour_power_w must be >= 0 (got -1)");
  c = RecipeConfig();
  c.hatch_power_w = 0.0;  // 0 W is allowed
  EXPECT_EQ(validationMessage(c), "");
  c.laser_on_delay_s = -1e-3;  // any sign
  c.laser_off_delay_s = -2e-4;
  EXPECT_EQ(validationMessage(c), "");
  c.laser_off_delay_s = std::nan("");
  EXPECT_EQ(validationMessage(c), "recipe.laser_off_delay_s must be finite (got nan)");
  c.laser_off_delay_s = 0.0;
  c.laser_on_delay_s = -std::numeric_limits<double>::infinity();
  EXPECT_EQ(validationMessage(c), "recipe.laser_on_delay_s must be finite (got -inf)");
}

// A job with every role: contour, jump, contour (contour jump), jump, hatch, jump, unspecified,
// a dwell, jump, contour, two jumps in a row, contour. Exact: speeds and powers are copied.
TEST(Recipe, ApplyRecipeByRole)
{
  Job job;
  job.name = "roles";
  job.polylines.push_back(mark(PolylineRole::Contour, {{0, 0}, {1e-3, 0}, {1e-3, 1e-3}}));  // 0
  job.polylines.push_back(jump({{1e-3, 1e-3}, {2e-3, 0}}));                                 // 1: contour jump
  job.polylines.push_back(mark(PolylineRole::Contour, {{2e-3, 0}, {3e-3, 0}}));             // 2
  job.polylines.push_back(jump({{3e-3, 0}, {4e-3, 0}}));                                    // 3: contour→hatch
  job.polylines.push_back(mark(PolylineRole::Hatch, {{4e-3, 0}, {5e-3, 0}}));               // 4
  job.polylines.push_back(jump({{5e-3, 0}, {6e-3, 0}}));                                    // 5: hatch→unspecified
  job.polylines.push_back(mark(PolylineRole::Unspecified, {{6e-3, 0}, {7e-3, 0}}));         // 6
  scanhead::Polyline spot = mark(PolylineRole::Hatch, {{7e-3, 0}});                         // 7: dwell
  spot.dwell_s = 2e-3;
  spot.speed_mps = 0.0;
  job.polylines.push_back(spot);
  job.polylines.push_back(jump({{7e-3, 0}, {8e-3, 0}}));                                 // 8
  job.polylines.push_back(mark(PolylineRole::Contour, {{8e-3, 0}, {9e-3, 0}}));          // 9
  job.polylines.push_back(jump({{9e-3, 0}, {9e-3, 1e-3}}));                              // 10: jump→jump
  job.polylines.push_back(jump({{9e-3, 1e-3}, {10e-3, 1e-3}}));                          // 11
  job.polylines.push_back(mark(PolylineRole::Contour, {{10e-3, 1e-3}, {11e-3, 1e-3}}));  // 12

  Recipe r;
  r.override_job = true;
  r.contour_speed_mps = 1.5;
  r.contour_power_w = 180.0;
  r.hatch_speed_mps = 1.1;
  r.hatch_power_w = 210.0;
  r.jump_speed_mps = 7.0;
  r.contour_jump_speed_mps = 4.2;
  const Job out = scanhead::applyRecipe(job, r);
  ASSERT_EQ(out.polylines.size(), job.polylines.size());
  const double expected_speed[] = {1.5, 4.2, 1.5, 7.0, 1.1, 7.0, 1.1, 0.0, 7.0, 1.5, 7.0, 7.0, 1.5};
  for (std::size_t p = 0; p < out.polylines.size(); ++p)
  {
    EXPECT_EQ(out.polylines[p].speed_mps, expected_speed[p]) << "polyline " << p;
    EXPECT_EQ(out.polylines[p].points, job.polylines[p].points) << "polyline " << p;
    EXPECT_EQ(out.polylines[p].type, job.polylines[p].type) << "polyline " << p;
  }
  EXPECT_EQ(out.polylines[0].power_w, 180.0);
  EXPECT_EQ(out.polylines[2].power_w, 180.0);
  EXPECT_EQ(out.polylines[4].power_w, 210.0);
  EXPECT_EQ(out.polylines[6].power_w, 210.0);  // unspecified = hatch
  EXPECT_EQ(out.polylines[7].power_w, 210.0);  // the dwell takes the power, keeps its time
  EXPECT_EQ(out.polylines[7].dwell_s, 2e-3);
  EXPECT_EQ(out.polylines[9].power_w, 180.0);

  // "job": a copy, unchanged
  r.override_job = false;
  const Job same = scanhead::applyRecipe(job, r);
  for (std::size_t p = 0; p < job.polylines.size(); ++p)
  {
    EXPECT_EQ(same.polylines[p].speed_mps, job.polylines[p].speed_mps);
    EXPECT_EQ(same.polylines[p].power_w, job.polylines[p].power_w);
  }
}
