/// \file test_job_placement.cpp
/// \brief Issue 16, item 1: plate-frame jobs placed on the field (cam.offset_m, cam.rotation_deg, cam.centre), what
/// column 5 of a segment file is (cam.segment_power), and segment files split into layers where z changes.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "fixtures/chain_fixture.hpp"
#include "scanhead/chain/config_io.hpp"
#include "scanhead/common/errors.hpp"
#include "scanhead/job/formats/job_io.hpp"
#include "scanhead/job/formats/segment_path.hpp"
#include "scanhead/job/job_files.hpp"
#include "scanhead/job/job_placement.hpp"

using scanhead::CamConfig;
using scanhead::InputError;
using scanhead::Job;
using scanhead::loadJob;
using scanhead::PolylineType;

namespace
{
namespace fs = std::filesystem;

/// \brief A file in a fresh folder under the test's temporary directory.
std::string writeFile(const std::string& name, const std::string& text)
{
  const fs::path dir = fs::path(::testing::TempDir()) / "job_placement";
  fs::create_directories(dir);
  const fs::path path = dir / name;
  std::ofstream(path) << text;
  return path.string();
}

/// \brief A 3DThesis/Myna layer in the plate's frame (mm, tab-separated, column 5 a 0/1 laser flag), like the ORNL
/// Peregrine layers: two 4 mm hatch lines at 0.8 m/s around (200, 20) mm, z = \p z_mm, then (if \p second_z_mm > 0)
/// a second layer at that z, 1 mm to the right.
std::string plateLayer(double z_mm, double second_z_mm = 0.0)
{
  auto rows = [](double z, double dx) {
    const std::string zs = std::to_string(z);
    auto x = [dx](double v) { return std::to_string(v + dx); };
    return "1\t" + x(198.0) + "\t19.0\t" + zs + "\t0\t0.000\n" +  // go to the start
           "0\t" + x(202.0) + "\t19.0\t" + zs + "\t1\t0.800\n" +  // mark 4 mm
           "0\t" + x(202.0) + "\t19.1\t" + zs + "\t0\t2.000\n" +  // jump 0.1 mm
           "0\t" + x(198.0) + "\t19.1\t" + zs + "\t1\t0.800\n";   // mark 4 mm back
  };
  std::string text = "Mode\tX(mm)\tY(mm)\tZ(mm)\tPmod\ttParam\n" + rows(z_mm, 0.0);
  if (second_z_mm > 0.0)
    text += rows(second_z_mm, 1.0);
  return text;
}

CamConfig plateCam()
{
  CamConfig cam;
  cam.units = "mm";
  cam.mark_power_w = 200.0;
  return cam;
}

double markEnergy(const Job& job)
{
  double e = 0.0;
  for (const auto& line : job.polylines)
    if (line.type == PolylineType::Mark)
      for (std::size_t k = 1; k < line.points.size(); ++k)
        e += line.power_w * (line.points[k] - line.points[k - 1]).norm() / line.speed_mps;
  return e;
}

std::string loadError(const std::string& argument, const CamConfig& cam)
{
  try
  {
    const Job job = loadJob(argument, cam);
    scanhead::validateScanJob(job, 0.175);
  }
  catch (const InputError& e)
  {
    return e.what();
  }
  return "";
}
}  // namespace

// The offset moves every point by exactly the offset; a quarter turn is exact; another angle is R·p + o.
TEST(JobPlacement, OffsetAndRotation)
{
  CamConfig cam;
  const Job plain = loadJob("corner", cam);
  cam.offset_m = {0.01, -0.02};
  const Job moved = loadJob("corner", cam);
  cam.rotation_deg = 90.0;
  const Job turned = loadJob("corner", cam);
  cam.rotation_deg = 30.0;
  const Job angled = loadJob("corner", cam);
  const double c = std::cos(M_PI / 6.0), s = std::sin(M_PI / 6.0);
  ASSERT_EQ(plain.polylines.size(), moved.polylines.size());
  for (std::size_t i = 0; i < plain.polylines.size(); ++i)
    for (std::size_t k = 0; k < plain.polylines[i].points.size(); ++k)
    {
      const Eigen::Vector2d p = plain.polylines[i].points[k];
      EXPECT_EQ(moved.polylines[i].points[k], p + Eigen::Vector2d(0.01, -0.02));
      EXPECT_EQ(turned.polylines[i].points[k], Eigen::Vector2d(-p.y(), p.x()) + Eigen::Vector2d(0.01, -0.02));
      EXPECT_NEAR(
          (angled.polylines[i].points[k] - Eigen::Vector2d(c * p.x() - s * p.y() + 0.01, s * p.x() + c * p.y() - 0.02))
              .norm(),
          0.0, 1e-15);
    }
  EXPECT_EQ(angled.placement.rotation_deg, 30.0);
  EXPECT_EQ(angled.placement.offset_m, Eigen::Vector2d(0.01, -0.02));
  EXPECT_FALSE(angled.placement.centred);
  // Nothing asked: the job as read, bit for bit, and no placement recorded.
  EXPECT_TRUE(plain.placement.identity());
  EXPECT_EQ(scanhead::scanJobToYaml(plain).find("placement"), std::string::npos);
}

// A plate-frame file is refused with the fix in the message; cam.centre puts its bounding-box centre on the field
// centre (plus cam.offset_m), and the marks' energy is P·t at the chosen power (column 5 a 0/1 flag).
TEST(JobPlacement, CentringAPlateFrameFile)
{
  const std::string path = writeFile("plate.txt", plateLayer(2.5));
  CamConfig cam = plateCam();
  const std::string error = loadError(path, cam);
  EXPECT_NE(error.find("lies outside the field"), std::string::npos) << error;
  EXPECT_NE(error.find("--set cam.centre=true"), std::string::npos) << error;
  EXPECT_NE(error.find("cam.offset_m=[-0.2,-0.01905]"), std::string::npos) << error;
  cam.centre = true;
  Job job = loadJob(path, cam);
  Eigen::Vector2d lo, hi;
  ASSERT_TRUE(scanhead::rotatedBoundingBox(job, 0.0, lo, hi));
  EXPECT_NEAR(lo.x() + hi.x(), 0.0, 1e-15);
  EXPECT_NEAR(lo.y() + hi.y(), 0.0, 1e-15);
  EXPECT_NEAR(hi.x() - lo.x(), 4e-3, 1e-15);
  EXPECT_TRUE(job.placement.centred);
  EXPECT_NEAR(job.placement.offset_m.x(), -0.2, 1e-15);
  // Two 4 mm marks at 0.8 m/s, 200 W: 2 × 200 × 0.004 / 0.8 = 2 J.
  EXPECT_NEAR(markEnergy(job), 2.0, 1e-12);
  cam.offset_m = {0.05, 0.0};
  job = loadJob(path, cam);
  ASSERT_TRUE(scanhead::rotatedBoundingBox(job, 0.0, lo, hi));
  EXPECT_NEAR(0.5 * (lo.x() + hi.x()), 0.05, 1e-15);
  // The placement survives job.yaml: a re-read job keeps it (the points are already placed).
  const Job again = scanhead::parseScanJobYaml(scanhead::scanJobToYaml(job), "job.yaml");
  EXPECT_EQ(again.placement.offset_m, job.placement.offset_m);
  EXPECT_TRUE(again.placement.centred);
  EXPECT_EQ(again.polylines[1].points, job.polylines[1].points);
}

// The whole chain on the placed file deposits what the marks command (P·t) and metrics.yaml names the placement.
TEST(JobPlacement, PlacedFileThroughTheChain)
{
  const std::string path = writeFile("plate_chain.txt", plateLayer(2.5));
  const std::string out = (fs::path(::testing::TempDir()) / "job_placement_results").string();
  fs::remove_all(out);
  const auto run = scanhead::test_support::runJob(path, {"cam.units=mm", "cam.centre=true"}, out);
  EXPECT_NEAR(run.metrics.commanded_energy_j, 2.0, 2.0 * 1e-3);  // the gate's sample rounding: ≤ 1 sample of 10 µs
  EXPECT_NEAR(run.metrics.deposited_energy_j, run.metrics.commanded_energy_j, 1e-6 * 2.0);  // float map
  std::ifstream metrics(out + "/metrics.yaml");
  const std::string text((std::istreambuf_iterator<char>(metrics)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("placement: {rotation_deg: 0, offset_m: [-0.20000000000000001, -0.019050000000000001], "
                      "centred: true}"),
            std::string::npos)
      << text.substr(0, 300);
}

// Column 5: "Pmod" and values <= 1 are coefficients, "Power" or a value > 1 watts; the setting overrides.
TEST(JobPlacement, SegmentPowerColumn)
{
  using scanhead::parseSegmentPath;
  using scanhead::SegmentPower;
  using scanhead::SegmentReadOptions;
  SegmentReadOptions options;
  options.power_w = 300.0;
  auto power = [&](const std::string& header, double column5, SegmentPower rule) {
    options.power_column = rule;
    const std::string text = header + "\n1 0 0 0 0 0\n0 0.001 0 0 " + std::to_string(column5) + " 1\n";
    return parseSegmentPath(text, "p.txt", options).polylines.back().power_w;
  };
  EXPECT_EQ(power("Mode X(mm) Y(mm) Z(mm) Pmod tParam", 1.0, SegmentPower::Auto), 300.0);  // 3DThesis, Peregrine
  EXPECT_EQ(power("Mode X Y Z Power Param", 1.0, SegmentPower::Auto), 1.0);                // AdditiveFOAM: W
  EXPECT_EQ(power("Mode X Y Z Power Param", 250.0, SegmentPower::Auto), 250.0);
  EXPECT_EQ(power("Mode a b c d e", 0.5, SegmentPower::Auto), 150.0);            // unnamed, <= 1: a coefficient
  EXPECT_EQ(power("Mode a b c d e", 180.0, SegmentPower::Auto), 180.0);          // unnamed, > 1: W
  EXPECT_EQ(power("2\nMode x y z pmod param", 0.5, SegmentPower::Auto), 150.0);  // adamantine
  EXPECT_EQ(power("Mode X Y Z Power Param", 1.0, SegmentPower::Coefficient), 300.0);
  EXPECT_EQ(power("Mode X(mm) Y(mm) Z(mm) Pmod tParam", 1.0, SegmentPower::Watts), 1.0);
  // Through the cam settings.
  const std::string path = writeFile("flags.txt", plateLayer(2.5));
  CamConfig cam = plateCam();
  cam.centre = true;
  cam.segment_power = "watts";
  EXPECT_NEAR(markEnergy(loadJob(path, cam)), 2.0 / 200.0, 1e-12);  // 1 W
}

// z changes start layers: cam.layer picks one (-1: all); a missing layer names how many there are; cam.centre
// centres the whole file, so both layers keep their relative offset (1 mm in x).
TEST(JobPlacement, SegmentLayersByZ)
{
  const std::string path = writeFile("two_layers.txt", plateLayer(2.5, 2.55));
  CamConfig cam = plateCam();
  cam.centre = true;
  cam.layer = 0;
  const Job first = loadJob(path, cam);
  cam.layer = 1;
  const Job second = loadJob(path, cam);
  cam.layer = -1;
  const Job all = loadJob(path, cam);
  EXPECT_NEAR(markEnergy(first), 2.0, 1e-12);
  EXPECT_NEAR(markEnergy(second), 2.0, 1e-12);
  EXPECT_NEAR(markEnergy(all), 4.0, 1e-12);
  EXPECT_EQ(first.placement.offset_m, second.placement.offset_m);  // one placement for the build
  EXPECT_NEAR(second.polylines[0].points[0].x() - first.polylines[0].points[0].x(), 1e-3, 1e-12);
  cam.layer = 2;
  const std::string error = loadError(path, cam);
  EXPECT_NE(error.find("cam.layer: the file has 2 layer(s)"), std::string::npos) << error;
}

// The readers survey the whole file while they keep one layer (file_survey.hpp): every layer read alone reports the
// layer count, the bounding box of the file read whole (bit for bit, after cam.rotation_deg) and each layer's path
// time Σ length / speed + dwell, computed here again from the whole file's polylines.
TEST(JobPlacement, SurveyOfTheWholeFile)
{
  const std::string segment = writeFile("survey_layers.txt", plateLayer(2.5, 2.55));
  const std::string cli = std::string(SCANHEAD_SOURCE_DIR) + "/test/data/cli/cli_full.cli";
  for (const std::string& path : {segment, cli})
  {
    CamConfig cam = plateCam();
    cam.layer = -1;
    const Job whole = loadJob(path, cam);
    Eigen::Vector2d lo, hi;
    ASSERT_TRUE(scanhead::rotatedBoundingBox(whole, 30.0, lo, hi)) << path;
    double path_s = 0.0;
    for (const auto& line : whole.polylines)
    {
      path_s += line.dwell_s;
      for (std::size_t k = 1; k < line.points.size(); ++k)
        path_s += (line.points[k] - line.points[k - 1]).norm() / line.speed_mps;
    }
    ASSERT_EQ(whole.file.layers, 2u) << path;
    for (int layer = 0; layer < 2; ++layer)
    {
      cam.rotation_deg = 30.0;
      cam.layer = layer;
      const Job one = loadJob(path, cam);
      EXPECT_TRUE(one.file.surveyed);
      EXPECT_EQ(one.file.layers, 2u);
      EXPECT_EQ(one.file.box_lo, lo) << path;
      EXPECT_EQ(one.file.box_hi, hi) << path;
      ASSERT_EQ(one.file.layer_path_s.size(), 2u);
      EXPECT_NEAR(one.file.layer_path_s[0] + one.file.layer_path_s[1], path_s, 1e-15) << path;
    }
  }
  // The plate layers by hand: two 4 mm marks at 0.8 m/s and a 0.1 mm jump at 2 m/s each.
  CamConfig cam = plateCam();
  const Job first = loadJob(segment, cam);
  EXPECT_NEAR(first.file.layer_path_s[0], 2 * 0.004 / 0.8 + 0.0001 / 2.0, 1e-15);
  EXPECT_NEAR(first.file.layer_path_s[1], 2 * 0.004 / 0.8 + 0.0001 / 2.0, 1e-15);
  // A built-in job is its own whole: not surveyed, cam.centre uses its points.
  EXPECT_FALSE(loadJob("corner", CamConfig()).file.surveyed);
}

// cam.offset_m is a list in the config file and after --set; it round-trips through the written config; bad values
// name the key.
TEST(JobPlacement, OffsetSetting)
{
  using scanhead::loadChainConfig;
  EXPECT_EQ(loadChainConfig("", {"cam.offset_m=[0.01, -0.002]"}).cam.offset_m[1], -0.002);
  EXPECT_EQ(loadChainConfig("", {"cam.offset_m=0.01,0.02"}).cam.offset_m[0], 0.01);
  const std::string yaml = scanhead::chainConfigToYaml(loadChainConfig("", {"cam.offset_m=[0.1,0.2]"}));
  EXPECT_NE(yaml.find("offset_m: [0.10000000000000001, 0.20000000000000001]"), std::string::npos);
  const std::string file = writeFile("config.yaml", yaml);
  EXPECT_EQ(loadChainConfig(file, {}).cam.offset_m[1], 0.2);
  auto error = [](const std::string& assignment) {
    try
    {
      loadChainConfig("", {assignment});
    }
    catch (const std::exception& e)
    {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(error("cam.offset_m=[1]").find("cam.offset_m"), std::string::npos);
  EXPECT_NE(error("cam.offset_m=[a,b]").find("cam.offset_m[0]"), std::string::npos);
  EXPECT_NE(error("cam.offset_m=[1e9,0]").find("cam.offset_m[0]"), std::string::npos);
  EXPECT_NE(error("cam.segment_power=volts").find("cam.segment_power"), std::string::npos);
  EXPECT_NE(error("cam.rotation_deg=1000").find("cam.rotation_deg"), std::string::npos);
}
