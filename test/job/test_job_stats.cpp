/// \file test_job_stats.cpp
/// \brief Job statistics against a job computed by hand (explicit and implicit jumps, groups).
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include "fixtures/polyline_fixture.hpp"
#include "scanhead/common/errors.hpp"
#include "scanhead/job/job_stats.hpp"

namespace scanhead
{
namespace
{
using scanhead::test_support::line;

/// By hand (lengths in mm, speeds in m/s so mm / (m/s) = ms):
///  P0 MARK 2 m/s 100 W: 3 + 4 = 7 mm -> 3.5 ms, 0.35 J
///  P1 JUMP 5 m/s: 3 mm -> 0.6 ms
///  implicit jump (0,4) -> (0,8) mm at 4 m/s: 4 mm -> 1 ms
///  P2 MARK 1 m/s 50 W: 2 mm -> 2 ms, 0.1 J
///  P3 MARK 1 m/s 50 W, contiguous with P2, a repeated first point: 6 mm -> 6 ms, 0.3 J
Job handJob()
{
  Job job;
  job.name = "hand \"job\"";
  job.polylines.push_back(line(PolylineType::Mark, 2.0, 100.0, {{0.0, 0.0}, {0.003, 0.0}, {0.003, 0.004}}));
  job.polylines.push_back(line(PolylineType::Jump, 5.0, 0.0, {{0.003, 0.004}, {0.0, 0.004}}));
  job.polylines.push_back(line(PolylineType::Mark, 1.0, 50.0, {{0.0, 0.008}, {0.0, 0.010}}));
  job.polylines.push_back(line(PolylineType::Mark, 1.0, 50.0, {{0.0, 0.010}, {0.0, 0.010}, {0.006, 0.010}}));
  return job;
}

// Sums of a handful of doubles: relative rounding ~1e-15; 1e-12 leaves margin, any modelling
// error (a missing segment, a wrong speed) is >= 1e-4 relative here.
constexpr double kRel = 1e-12;
}  // namespace

TEST(JobStats, HandComputedJobWithImplicitJump)
{
  const JobStats s = computeJobStats(handJob(), 4.0);
  EXPECT_EQ(s.polyline_count, 4u);
  EXPECT_EQ(s.mark_polyline_count, 3u);
  EXPECT_EQ(s.jump_polyline_count, 1u);
  EXPECT_EQ(s.mark_count, 4u);  // the zero-length edge of P3 is not a segment
  EXPECT_EQ(s.jump_count, 2u);
  EXPECT_EQ(s.implicit_jump_count, 1u);
  EXPECT_NEAR(s.mark_length_m, 0.015, 0.015 * kRel);
  EXPECT_NEAR(s.jump_length_m, 0.007, 0.007 * kRel);
  EXPECT_NEAR(s.implicit_jump_length_m, 0.004, 0.004 * kRel);
  EXPECT_NEAR(s.mark_time_s, 11.5e-3, 11.5e-3 * kRel);
  EXPECT_NEAR(s.jump_time_s, 1.6e-3, 1.6e-3 * kRel);
  EXPECT_NEAR(s.ideal_time_s, 13.1e-3, 13.1e-3 * kRel);
  EXPECT_NEAR(s.laser_on_energy_j, 0.75, 0.75 * kRel);
  ASSERT_TRUE(s.has_points);
  EXPECT_EQ(s.bbox_min_m, Eigen::Vector2d(0.0, 0.0));
  EXPECT_EQ(s.bbox_max_m, Eigen::Vector2d(0.006, 0.010));
  ASSERT_TRUE(s.has_marks);
  EXPECT_EQ(s.mark_bbox_max_m, Eigen::Vector2d(0.006, 0.010));
  EXPECT_TRUE(s.groups.empty());
}

TEST(JobStats, ImplicitJumpSpeedChangesOnlyTheImplicitJumpTime)
{
  // 4 mm implicit jump at 8 m/s instead of 4: 0.5 ms less.
  const JobStats s = computeJobStats(handJob(), 8.0);
  EXPECT_NEAR(s.ideal_time_s, 12.6e-3, 12.6e-3 * kRel);
  EXPECT_NEAR(s.jump_length_m, 0.007, 0.007 * kRel);
}

TEST(JobStats, GroupTimesIncludeTheLeadingImplicitJump)
{
  const JobStats s = computeJobStats(handJob(), 4.0, {0, 0, 1, 1});
  ASSERT_EQ(s.groups.size(), 2u);
  EXPECT_EQ(s.groups[1].group, 1);
  EXPECT_NEAR(s.groups[0].time_s, 4.1e-3, 4.1e-3 * kRel);       // P0 + P1
  EXPECT_NEAR(s.groups[1].time_s, 9.0e-3, 9.0e-3 * kRel);       // implicit jump + P2 + P3
  EXPECT_NEAR(s.groups[1].jump_length_m, 0.004, 0.004 * kRel);  // the implicit jump
  EXPECT_NEAR(s.groups[1].mark_length_m, 0.008, 0.008 * kRel);
  EXPECT_NEAR(s.groups[0].time_s + s.groups[1].time_s, s.ideal_time_s, s.ideal_time_s * kRel);

  const JobStats untagged = computeJobStats(handJob(), 4.0, {-1, 2, -1, -1});
  ASSERT_EQ(untagged.groups.size(), 3u);  // groups 0 and 1 exist but are empty
  EXPECT_EQ(untagged.groups[0].time_s, 0.0);
  EXPECT_NEAR(untagged.groups[2].time_s, 0.6e-3, 0.6e-3 * kRel);
}

TEST(JobStats, DwellsAddTimeAndEnergyButNoLength)
{
  // + a 2 ms MARK spot at 50 W where P3 ends (no implicit jump), + a 1 ms JUMP spot 10 mm below
  // it (implicit jump of 10 mm at 4 m/s = 2.5 ms, laser off during the spot).
  Job job = handJob();
  Polyline spot;
  spot.type = PolylineType::Mark;
  spot.power_w = 50.0;
  spot.dwell_s = 2e-3;
  spot.points = {{0.006, 0.010}};
  job.polylines.push_back(spot);
  spot.type = PolylineType::Jump;
  spot.dwell_s = 1e-3;
  spot.points = {{0.006, 0.0}};
  job.polylines.push_back(spot);
  const JobStats s = computeJobStats(job, 4.0, {0, 0, 1, 1, 1, 2});
  EXPECT_EQ(s.dwell_count, 2u);
  EXPECT_EQ(s.mark_count, 4u);
  EXPECT_EQ(s.implicit_jump_count, 2u);
  EXPECT_NEAR(s.dwell_time_s, 3e-3, 3e-3 * kRel);
  EXPECT_NEAR(s.mark_length_m, 0.015, 0.015 * kRel);
  EXPECT_NEAR(s.mark_time_s, 11.5e-3, 11.5e-3 * kRel);
  EXPECT_NEAR(s.jump_time_s, 4.1e-3, 4.1e-3 * kRel);
  EXPECT_NEAR(s.ideal_time_s, 13.1e-3 + 2e-3 + 2.5e-3 + 1e-3, 18.6e-3 * kRel);
  EXPECT_NEAR(s.laser_on_energy_j, 0.75 + 0.1, 0.85 * kRel);  // + 50 W × 2 ms; the jump spot adds none
  ASSERT_EQ(s.groups.size(), 3u);
  EXPECT_NEAR(s.groups[1].time_s, 11e-3, 11e-3 * kRel);
  EXPECT_NEAR(s.groups[2].time_s, 3.5e-3, 3.5e-3 * kRel);
  EXPECT_NEAR(s.groups[2].dwell_time_s, 1e-3, 1e-3 * kRel);
}

TEST(JobStats, RejectsBadArguments)
{
  EXPECT_THROW(computeJobStats(handJob(), 4.0, {0, 1}), ConfigError);
  EXPECT_THROW(computeJobStats(handJob(), 0.0), ConfigError);  // an implicit jump is needed
  Job bad = handJob();
  bad.polylines[1].speed_mps = -1.0;
  EXPECT_THROW(computeJobStats(bad, 4.0), InputError);
}

TEST(JobStats, EmptyJobIsAllZero)
{
  const JobStats s = computeJobStats(Job{}, 4.0);
  EXPECT_FALSE(s.has_points);
  EXPECT_EQ(s.ideal_time_s, 0.0);
  EXPECT_EQ(s.mark_count + s.jump_count, 0u);
}

TEST(JobStats, YamlCarriesTheScriptKeysExactly)
{
  const JobStats s = computeJobStats(handJob(), 4.0, {0, 0, 1, 1});
  const YAML::Node y = YAML::Load(jobStatsYaml(s));
  EXPECT_EQ(y["name"].as<std::string>(), "hand \"job\"");
  // Printed with round-trip precision: equal, not near.
  EXPECT_EQ(y["mark_length_m"].as<double>(), s.mark_length_m);
  EXPECT_EQ(y["jump_length_m"].as<double>(), s.jump_length_m);
  EXPECT_EQ(y["ideal_time_s"].as<double>(), s.ideal_time_s);
  EXPECT_EQ(y["laser_on_energy_j"].as<double>(), s.laser_on_energy_j);
  EXPECT_EQ(y["implicit_jump_count"].as<int>(), 1);
  EXPECT_EQ(y["bbox_max_m"][1].as<double>(), 0.010);
  ASSERT_EQ(y["groups"].size(), 2u);
  EXPECT_EQ(y["groups"][1]["time_s"].as<double>(), s.groups[1].time_s);
}
}  // namespace scanhead
