/// \file test_layer_report.cpp
/// \brief The layer report end to end: metrics.yaml's interface for scripts, the layer time against
/// the job's own timeline, crops of the parts, the corner energy peak of the NC corner test, the
/// thermal view's time window, and the comparison of two recipes.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "fixtures/chain_fixture.hpp"
#include "scanhead/chain/results_writer.hpp"
#include "scanhead/common/errors.hpp"
#include "scanhead/job/generators/thesis_square_job.hpp"
#include "scanhead/metrics/metrics_report.hpp"
#include "scanhead/metrics/run_comparison.hpp"
#include "scanhead/report/energy_exports.hpp"

namespace fs = std::filesystem;
using namespace scanhead;
using scanhead::test_support::kConfig;

namespace
{
const std::string kTwoSquares = "squares:recipe=1,rows=1,columns=2";

struct Written
{
  fs::path dir;
  RunMetrics metrics;
};

/// Runs a job through the batch chain and writes its results folder (no plots: fast).
Written runAndWrite(const std::string& spec, const std::vector<std::string>& overrides, const std::string& name)
{
  Written w;
  w.dir = fs::temp_directory_path() / ("scanhead_layer_report_" + name);
  fs::remove_all(w.dir);
  w.metrics = test_support::runJob(spec, overrides, w.dir.string()).metrics;
  return w;
}
}  // namespace

// The keys scripts read (issue 7's interface), with values that make sense; the layer time is the
// job's own Σ L/v (the default NC adds no hold); the parts are the squares.
TEST(LayerReport, MetricsYamlInterfaceAndParts)
{
  const Written w = runAndWrite(kTwoSquares, {"energy.crop_parts=10"}, "squares");
  const YAML::Node m = YAML::LoadFile((w.dir / "metrics.yaml").string());
  for (const char* definition : {"same_instant", "nearest_path"})
  {
    const YAML::Node d = m["contour_error"][definition];
    ASSERT_TRUE(d.IsMap()) << definition;
    for (const char* share : {"share_under_10um", "share_under_20um", "share_under_30um"})
    {
      const double v = d[share].as<double>();
      EXPECT_GE(v, 0.0) << definition << "." << share;
      EXPECT_LE(v, 1.0) << definition << "." << share;
    }
    EXPECT_LE(d["share_under_10um"].as<double>(), d["share_under_20um"].as<double>());
    EXPECT_LE(d["share_under_20um"].as<double>(), d["share_under_30um"].as<double>());
    EXPECT_GT(d["contour"]["points"].as<std::uint64_t>(), 0u);
    EXPECT_GT(d["hatch"]["points"].as<std::uint64_t>(), 0u);
    EXPECT_GT(d["jump"]["points"].as<std::uint64_t>(), 0u);
  }
  const double fill = m["fill_rate"].as<double>();
  EXPECT_GT(fill, 0.9);
  EXPECT_LE(fill, 1.0);
  EXPECT_GT(m["peak_memory_bytes"].as<std::uint64_t>(), 0u);
  const SquareJob squares = makeSquareJob(
      [] {
        SquareJobParams p;
        p.rows = 1;
        p.columns = 2;
        return p;
      }(),
      thesisRecipe(1));
  double ideal = 0.0;
  for (double t : squareTimes(squares))
    ideal += t;
  EXPECT_NEAR(m["layer_time_s"].as<double>(), ideal, 1e-9 * ideal);
  // Angle errors are sampled over the program; both axes see the same count.
  EXPECT_EQ(m["angle_error"]["x"]["count"].as<std::uint64_t>(),
            m["contour_error"]["commanded_points"].as<std::uint64_t>());
  // One crop per square, at full resolution, plus the overview images.
  for (const char* file :
       {"energy_map.png", "energy_map_16bit.png", "energy_map.tiff", "energy_map.yaml", "crops/part_000.png",
        "crops/part_000.tiff", "crops/part_001_16bit.png", "crops/part_001.yaml"})
    EXPECT_TRUE(fs::exists(w.dir / file)) << file;
  EXPECT_FALSE(fs::exists(w.dir / "crops/part_002.png"));
  const YAML::Node crop = YAML::LoadFile((w.dir / "crops/part_000.yaml").string());
  EXPECT_EQ(crop["pixel_m"].as<double>(), 5e-6);
  EXPECT_NEAR(crop["width"].as<double>() * 5e-6, 10e-3 + 4 * 70e-6, 2 * 5e-6);  // the square + 2 spot diameters a side
  fs::remove_all(w.dir);
}

// The NC paper's corner test (right angle, 1 m/s): the energy piles up where the spot slows. The
// speed falls to V·cos(45°) = 0.707 V (NC §3.2), so the line energy there is ≥ 1/0.707 = 1.41 of the
// straight level; the overlap of the two legs adds at most as much again (≤ 2 × 1.41 = 2.83).
TEST(LayerReport, CornerEnergyPeakOfTheNcCornerTest)
{
  const test_support::ChainRun run = test_support::runJob("corner:speed=1,angle=90", {});
  ASSERT_EQ(run.metrics.corners.size(), 1u);
  ASSERT_TRUE(run.metrics.track_measured);
  const double ratio = run.metrics.corners[0].energy_peak_jpm2 / run.metrics.track_median_jpm2;
  EXPECT_GT(ratio, 1.3);
  EXPECT_LT(ratio, 2.83);
  EXPECT_NEAR(run.metrics.corner_peak_to_track_mean_max,
              run.metrics.corners[0].energy_peak_jpm2 / run.metrics.track_mean_jpm2, 1e-12);
  std::cout << "corner 90 deg at 1 m/s: peak " << run.metrics.corners[0].energy_peak_jpm2 * 1e-6 << " J/mm^2, straight "
            << run.metrics.track_median_jpm2 * 1e-6 << " J/mm^2, ratio " << ratio << "\n";
}

// The thermal view runs on its time window only and reports the melt pool; off, it is null.
TEST(LayerReport, ThermalViewOnItsWindow)
{
  const test_support::ChainRun off = test_support::runJob("corner:speed=1,angle=90", {});
  EXPECT_FALSE(off.metrics.thermal_enabled);
  EXPECT_NE(metricsToYaml(off.metrics).find("thermal: null"), std::string::npos);
  const test_support::ChainRun on = test_support::runJob(
      "corner:speed=1,angle=90", {"thermal.enabled=true", "thermal.start_s=0.001", "thermal.duration_s=0.004"});
  ASSERT_TRUE(on.metrics.thermal_enabled);
  EXPECT_EQ(on.metrics.thermal_samples, 400u);
  EXPECT_GT(on.metrics.thermal_melt_pool.max_length_m, 70e-6);  // 200 W at 1 m/s melts a pool longer than the spot
  EXPECT_GT(on.metrics.thermal_melted_area_m2, 0.0);
  const ThermalEnergy& e = on.metrics.thermal_energy;
  EXPECT_NEAR(e.residual_j(), 0.0, 1e-9 * e.absorbed_j);
  // Absorbed = A·Σ P·Ts over the window's samples (all laser on: the marks last 8 ms from t = 0).
  EXPECT_NEAR(e.absorbed_j, 0.35 * 200.0 * 400 * 1e-5, 1e-9);
  EXPECT_THROW(loadChainConfig(kConfig, {"thermal.start_s=-1"}), ConfigError);
}

// Two recipes side by side (THESIS Table 3.1): recipe 2 marks the hatch faster, so its layer is shorter.
TEST(LayerReport, ComparisonOfTwoRecipes)
{
  const Written a = runAndWrite("squares:recipe=1,rows=1,columns=1", {}, "recipe1");
  const Written b = runAndWrite("squares:recipe=2,rows=1,columns=1", {}, "recipe2");
  const RunComparison c = compareMetricsFiles((a.dir / "metrics.yaml").string(), (b.dir / "metrics.yaml").string());
  EXPECT_EQ(c.name_a, "squares_recipe1");
  ASSERT_FALSE(c.rows.empty());
  EXPECT_EQ(c.rows[0].key, "layer_time_s");
  EXPECT_DOUBLE_EQ(c.rows[0].a, a.metrics.quality.layer_time_s);
  EXPECT_LT(c.rows[0].b, c.rows[0].a);
  bool found_fill = false;
  for (const ComparisonRow& r : c.rows)
    if (r.key == "fill_rate")
    {
      found_fill = true;
      EXPECT_DOUBLE_EQ(r.a, 100.0 * a.metrics.quality.fill_rate);
    }
  EXPECT_TRUE(found_fill);
  EXPECT_NE(comparisonTable(c).find("layer time"), std::string::npos);
  EXPECT_NE(comparisonMarkdown(c).find("| fill rate (hatch) | % |"), std::string::npos);
  // The shorter layer is the better one; the energy level ranks nothing.
  const std::string md = comparisonMarkdown(c);
  const std::string layer_line =
      md.substr(md.find("| layer time"), md.find('\n', md.find("| layer time")) - md.find("| layer time"));
  EXPECT_EQ(layer_line.substr(layer_line.size() - 5), "| B |") << layer_line;
  const std::string energy_line = md.substr(md.find("| mean energy along tracks"));
  EXPECT_EQ(energy_line.substr(energy_line.find('\n') - 4, 4), "|  |") << energy_line.substr(0, energy_line.find('\n'));
  const YAML::Node y = YAML::Load(comparisonYaml(c));
  EXPECT_EQ(y["rows"].size(), c.rows.size());
  EXPECT_THROW(compareMetricsFiles("/nonexistent/metrics.yaml", (b.dir / "metrics.yaml").string()), InputError);
  EXPECT_THROW(compareMetricsFiles((a.dir / "config.yaml").string(), (b.dir / "metrics.yaml").string()), InputError);
  fs::remove_all(a.dir);
  fs::remove_all(b.dir);
}

TEST(LayerReport, CropRegionsAreParsedOrNamed)
{
  const std::vector<MapRegion> r = parseMapRegions("0,0,1e-3,2e-3,left; -1e-3,-1e-3,0,0");
  ASSERT_EQ(r.size(), 2u);
  EXPECT_EQ(r[0].name, "left");
  EXPECT_EQ(r[1].name, "region_1");
  EXPECT_EQ(r[1].max_corner, Eigen::Vector2d(0, 0));
  EXPECT_TRUE(parseMapRegions("").empty());
  for (const char* bad : {"0,0,1", "0,0,x,1", "1,0,0,1", "0,0,1,1,a/b"})
  {
    try
    {
      parseMapRegions(bad);
      FAIL() << bad;
    }
    catch (const ConfigError& e)
    {
      EXPECT_NE(std::string(e.what()).find("energy.crop_regions"), std::string::npos) << e.what();
    }
  }
}
