/// \file test_nc_plan.cpp
/// \brief The NC's plan as a value: its figures are the NC's own, and the program rebuilt from its
/// segments (as the energy node receives it) is bit-identical, gate and timeline alike.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "fixtures/chain_fixture.hpp"
#include "scanhead/chain/energy_stage.hpp"
#include "scanhead/nc/nc_interpolator.hpp"
#include "scanhead/nc/nc_plan.hpp"
#include "scanhead/servo/galvo_servo.hpp"

using namespace scanhead;

namespace
{
// Holds, skywriting and delays: every kind of segment and a gate with shifted windows.
Job squareJob(const ChainConfig& config)
{
  return loadJob("squares:recipe=1,rows=1,columns=1,spacing=0.003", config.cam);
}

ChainConfig timingConfig()
{
  return loadChainConfig(test_support::kConfig,
                         {"recipe.preset=thesis1", "nc.skywriting.enabled=true", "nc.mark_delay_s=100e-6",
                          "nc.jump_delay_s=250e-6", "nc.polygon_delay_s=40e-6", "nc.polygon_delay_mode=angle"});
}
}  // namespace

TEST(NcPlan, HoldsTheNcsOwnFigures)
{
  const ChainConfig config = timingConfig();
  const OpticalModel optics = loadOpticalModel(config.optics);
  const Job job = squareJob(config);
  NcInterpolator nc(config.nc, resolveRecipe(config.recipe), optics, &config.servo);
  nc.start(job);
  const NcPlan& plan = nc.plan();
  EXPECT_EQ(plan.job_name, job.name);
  EXPECT_EQ(plan.total_samples, nc.totalSamples());
  EXPECT_EQ(plan.period_s, config.nc.period_s);
  EXPECT_EQ(plan.filter_delay_s, nc.stats().filter_delay_s);
  EXPECT_EQ(plan.gate_shift_s, nc.stats().gate_shift_s);
  EXPECT_EQ(plan.pathDuration(), nc.pathDuration());
  EXPECT_EQ(plan.servo_delay_s, GalvoServo(config.servo, config.nc.period_s).lowFrequencyDelay().maxCoeff());
  EXPECT_GT(plan.program.stats.polygon_holds + plan.program.stats.skywritten_corners, 0u);
  // The first setpoint sample is the plan's start, at rest.
  const NcOutput first = nc.process(1);
  EXPECT_EQ(first.setpoint.samples.front().position, plan.start_joints_rad);
}

TEST(NcPlan, WithoutTheServoModelHasNoServoDelayAndTheEnergyStageRefusesIt)
{
  const ChainConfig config = loadChainConfig(test_support::kConfig, {});
  const OpticalModel optics = loadOpticalModel(config.optics);
  const Job job = squareJob(config);
  NcInterpolator nc(config.nc, optics);
  nc.start(job);
  EXPECT_TRUE(std::isnan(nc.plan().servo_delay_s));
  EXPECT_THROW(EnergyStage(config, job, nc.plan()), std::invalid_argument);
}

TEST(NcPlan, ProgramRebuiltFromItsSegmentsIsBitIdentical)
{
  const ChainConfig config = timingConfig();
  const OpticalModel optics = loadOpticalModel(config.optics);
  NcInterpolator nc(config.nc, resolveRecipe(config.recipe), optics, &config.servo);
  nc.start(squareJob(config));
  const NcProgram& a = nc.plan().program;
  const NcProgram b = ncProgramFromSegments(a.timeline.segments(), a.laser_on_delay_s, a.laser_off_delay_s, a.stats);
  ASSERT_EQ(a.timeline.segments().size(), b.timeline.segments().size());
  for (std::size_t k = 0; k < a.timeline.segments().size(); ++k)
  {
    EXPECT_EQ(a.timeline.segments()[k].t_start_s, b.timeline.segments()[k].t_start_s) << k;
    EXPECT_EQ(a.timeline.segments()[k].end_m, b.timeline.segments()[k].end_m) << k;
  }
  EXPECT_EQ(a.timeline.duration(), b.timeline.duration());
  ASSERT_EQ(a.gate.windows().size(), b.gate.windows().size());
  ASSERT_GT(a.gate.windows().size(), 0u);
  LaserGate::Cursor ca, cb;
  for (std::size_t k = 0; k < a.gate.windows().size(); ++k)
  {
    EXPECT_EQ(a.gate.windows()[k].on_s, b.gate.windows()[k].on_s);
    EXPECT_EQ(a.gate.windows()[k].off_s, b.gate.windows()[k].off_s);
  }
  for (double t = 0.0; t < a.timeline.duration(); t += 7.3e-6)
    ASSERT_EQ(a.gate.powerAt(t, ca), b.gate.powerAt(t, cb)) << t;
}
