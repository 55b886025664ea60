// Job files: parsing, validation errors that name the file, line and field, round trip.
#include <gtest/gtest.h>

#include <cmath>

#include "scanhead/common/errors.hpp"
#include "scanhead/common/yaml_document.hpp"
#include "scanhead/job/formats/job_io.hpp"
#include "scanhead/job/generators/builtin_jobs.hpp"
#include "scanhead/job/job_files.hpp"

using namespace scanhead;

namespace
{
const std::string kData = std::string(SCANHEAD_SOURCE_DIR) + "/test/data/";

/// The InputError message of \p f, or "" if it did not throw.
template <class F>
std::string errorOf(F&& f)
{
  try
  {
    f();
  }
  catch (const InputError& e)
  {
    return e.what();
  }
  return "";
}

std::string job(const std::string& polyline_body)
{
  return "name: t\npolylines:\n  - " + polyline_body + "\n";
}
}  // namespace

TEST(JobIo, ReadsTheFullFixture)
{
  const Job j = loadScanJobFile(kData + "job_full.yaml");
  ASSERT_EQ(j.polylines.size(), 4u);
  EXPECT_EQ(j.name, "full");
  EXPECT_EQ(j.polylines[1].type, PolylineType::Jump);
  EXPECT_DOUBLE_EQ(j.polylines[0].points[2].y(), 0.0032);
  EXPECT_NO_THROW(validateScanJob(j, 0.175));
}

TEST(JobIo, RoundTripIsExact)
{
  const Job a = builtinJob("corner:speed=1.7,angle=108.43");
  const Job b = parseScanJobYaml(scanJobToYaml(a), "round trip");
  ASSERT_EQ(a.polylines.size(), b.polylines.size());
  for (std::size_t i = 0; i < a.polylines.size(); ++i)
  {
    EXPECT_EQ(a.polylines[i].speed_mps, b.polylines[i].speed_mps);
    EXPECT_EQ(a.polylines[i].power_w, b.polylines[i].power_w);
    for (std::size_t k = 0; k < a.polylines[i].points.size(); ++k)
      EXPECT_EQ(a.polylines[i].points[k], b.polylines[i].points[k]);  // %.17g: bit-exact
  }
}

TEST(JobIo, BoundedReading)
{
  // Duplicate keys: the second occurrence, with its line and column (yaml-cpp kept both; the
  // reader used to take the first).
  EXPECT_EQ(errorOf([] {
              parseScanJobYaml(job("{type: mark, speed: 1, power: 1, speed: 2, points: [[0,0],[1e-3,0]]}"), "f.yaml");
            }),
            "f.yaml:3:38: duplicate key 'polylines[0].speed' (first at line 3)");
  // Aliases are read (a shared point list) but their expansion is bounded by the text's size.
  const Job shared = parseScanJobYaml(
      "name: a\npolylines:\n  - {type: mark, speed: 1, power: 1, points: &p [[0, 0], [1e-3, 0]]}\n"
      "  - {type: jump, speed: 5, points: *p}\n",
      "f.yaml");
  EXPECT_EQ(shared.polylines[1].points, shared.polylines[0].points);
  std::string bomb = "name: b\nl0: &l0 [[0, 0], [1e-3, 0]]\n";
  for (int k = 1; k <= 8; ++k)
  {
    bomb += "l" + std::to_string(k) + ": &l" + std::to_string(k) + " [";
    for (int i = 0; i < 8; ++i)
      bomb += (i ? ", *l" : "*l") + std::to_string(k - 1);
    bomb += "]\n";
  }
  EXPECT_NE(errorOf([&] { parseScanJobYaml(bomb + "polylines: *l8\n", "bomb.yaml"); }).find("YAML aliases expand"),
            std::string::npos);
  // A key that is not a name.
  EXPECT_NE(errorOf([] { parseScanJobYaml("name: t\n? [a, b]\n: 1\n", "f.yaml"); }).find("a key is not a name"),
            std::string::npos);
  // Size: refused before parsing, with what to do instead.
  const std::string big(yamlJobLimits().max_bytes + 1, '#');
  const std::string message = errorOf([&] { parseScanJobYaml(big, "big.yaml"); });
  EXPECT_EQ(message.rfind("big.yaml: 8 MiB (8388609 bytes) is more than the 8 MiB a YAML job may have", 0), 0u)
      << message;
  EXPECT_NE(message.find("scanhead_job convert"), std::string::npos);
}

TEST(JobIo, NamesWithQuotesRoundTrip)
{
  Job a = builtinJob("corner");
  a.name = "a \"quoted\" \\ name\twith a tab";
  EXPECT_EQ(parseScanJobYaml(scanJobToYaml(a), "round trip").name, a.name);
}

TEST(JobIo, ErrorsNameFileLineAndField)
{
  EXPECT_NE(errorOf([] {
              loadScanJobFile(kData + "job_invalid_unknown_key.yaml");
            }).find("job_invalid_unknown_key.yaml:6: polylines[0]: unknown key 'colour'"),
            std::string::npos);
  EXPECT_NE(errorOf([] { loadScanJobFile(kData + "job_invalid_malformed.yaml"); }).find("malformed YAML"),
            std::string::npos);
  EXPECT_NE(errorOf([] { loadScanJobFile(kData + "no_such_file.yaml"); }).find("cannot open"), std::string::npos);
  EXPECT_NE(errorOf([] {
              parseScanJobYaml(job("{type: mark, speed: .nan, power: 1, points: [[0,0],[1e-3,0]]}"), "f.yaml");
            }).find("f.yaml:3: polylines[0].speed: '.nan' is not a number"),
            std::string::npos);
  EXPECT_NE(errorOf([] {
              parseScanJobYaml(job("{type: mark, speed: 1, power: 1, points: [[0,0]]}"), "f.yaml");
            }).find("polylines[0].points: needs at least 2 points (got 1)"),
            std::string::npos);
  EXPECT_NE(errorOf([] {
              parseScanJobYaml(job("{type: burn, speed: 1, power: 1, points: [[0,0],[1,0]]}"), "f.yaml");
            }).find("polylines[0].type: 'burn' is not mark or jump"),
            std::string::npos);
  EXPECT_NE(errorOf([] {
              parseScanJobYaml(job("{type: mark, speed: 1, power: 1, points: [[0,0],[1,x]]}"), "f.yaml");
            }).find("polylines[0].points[1].y: 'x' is not a number"),
            std::string::npos);
}

TEST(JobIo, ValidationNamesThePolylineAndValue)
{
  auto check = [](const std::string& body, const std::string& expected) {
    const Job j = parseScanJobYaml(job(body), "v.yaml");
    const std::string message = errorOf([&] { validateScanJob(j, 0.175); });
    EXPECT_NE(message.find(expected), std::string::npos) << message;
  };
  check("{type: mark, speed: 0, power: 1, points: [[0,0],[1e-3,0]]}", "polylines[0].speed must be > 0 m/s (got 0)");
  check("{type: mark, speed: -2, power: 1, points: [[0,0],[1e-3,0]]}", "speed must be > 0 m/s (got -2)");
  check("{type: mark, speed: 1, power: -5, points: [[0,0],[1e-3,0]]}", "power must be >= 0 W (got -5)");
  check("{type: mark, speed: 1, power: 1, points: [[0,0],[0.2,0]]}",
        "polylines[0].points[1] = (0.20000000000000001, 0) m lies outside the field");
}

// Dwells (spots): key `dwell` in s, exactly one point, speed optional; validation and round trip.
TEST(JobIo, DwellPolylines)
{
  const Job j = parseScanJobYaml(job("{type: mark, power: 100, dwell: 0.001, points: [[0.001, 0]]}"), "d.yaml");
  ASSERT_EQ(j.polylines.size(), 1u);
  EXPECT_EQ(j.polylines[0].dwell_s, 0.001);
  EXPECT_EQ(j.polylines[0].power_w, 100.0);
  ASSERT_EQ(j.polylines[0].points.size(), 1u);
  EXPECT_NO_THROW(validateScanJob(j, 0.175));
  const Job back = parseScanJobYaml(scanJobToYaml(j), "rt.yaml");
  EXPECT_EQ(back.polylines[0].dwell_s, 0.001);
  EXPECT_EQ(back.polylines[0].points, j.polylines[0].points);
  // a line has no dwell key on output
  EXPECT_EQ(scanJobToYaml(builtinJob("corner")).find("dwell"), std::string::npos);

  EXPECT_NE(errorOf([] {
              parseScanJobYaml(job("{type: mark, power: 1, dwell: 0.001, points: [[0,0],[1e-3,0]]}"), "f.yaml");
            }).find("f.yaml:3: polylines[0].points: a dwell needs exactly 1 point (got 2)"),
            std::string::npos);
  EXPECT_NE(errorOf([] {
              parseScanJobYaml(job("{type: mark, power: 1, dwell: -1, points: [[0,0]]}"), "f.yaml");
            }).find("f.yaml:3: polylines[0].dwell must be >= 0 s (got -1)"),
            std::string::npos);
  EXPECT_NE(errorOf([] {
              parseScanJobYaml(job("{type: mark, power: 1, dwell: 1e999, points: [[0,0]]}"), "f.yaml");
            }).find("polylines[0].dwell: '1e999' is not a finite number"),
            std::string::npos);
  // dwell 0 is a line: one point is not enough, and the speed is required
  EXPECT_NE(errorOf([] {
              parseScanJobYaml(job("{type: mark, speed: 1, power: 1, dwell: 0, points: [[0,0]]}"), "f.yaml");
            }).find("polylines[0].points: needs at least 2 points (got 1)"),
            std::string::npos);
  EXPECT_NE(errorOf([] {
              parseScanJobYaml(job("{type: mark, power: 1, points: [[0,0],[1e-3,0]]}"), "f.yaml");
            }).find("polylines[0].speed: missing (m/s)"),
            std::string::npos);

  auto invalid = [](void (*edit)(Polyline&)) {
    Job k = parseScanJobYaml(job("{type: mark, power: 1, dwell: 0.001, points: [[0,0]]}"), "v.yaml");
    edit(k.polylines[0]);
    return errorOf([&] { validateScanJob(k, 0.175); });
  };
  EXPECT_NE(invalid([](Polyline& p) { p.dwell_s = -2.0; }).find("v.yaml: polylines[0].dwell must be >= 0 s (got -2)"),
            std::string::npos);
  EXPECT_NE(invalid([](Polyline& p) { p.dwell_s = std::nan(""); }).find("polylines[0].dwell must be >= 0 s (got nan)"),
            std::string::npos);
  EXPECT_NE(invalid([](Polyline& p) {
              p.points.push_back({1e-3, 0});
            }).find("polylines[0].points: a dwell needs exactly 1 point (got 2)"),
            std::string::npos);
  EXPECT_NE(invalid([](Polyline& p) { p.dwell_s = 0.0; }).find("polylines[0].points: needs at least 2 points (got 1)"),
            std::string::npos);
  EXPECT_EQ(invalid([](Polyline& p) { p.speed_mps = 0.0; }), "");  // a dwell's speed is unused
  EXPECT_NE(invalid([](Polyline& p) {
              p.points[0] = {0.2, 0};
            }).find("polylines[0].points[0] = (0.20000000000000001, 0) m"),
            std::string::npos);
}

TEST(BuiltinJobs, CornerGeometry)
{
  const Job j = builtinJob("corner:speed=2,angle=53.13");
  ASSERT_EQ(j.polylines.size(), 1u);
  const auto& p = j.polylines[0].points;
  ASSERT_EQ(p.size(), 3u);
  // The example: (-0.004, 0) → (0, 0) → (0.0024, 0.0032) for γ = 53.13°.
  EXPECT_NEAR(p[2].x(), 0.0024, 1e-7);
  EXPECT_NEAR(p[2].y(), 0.0032, 1e-7);
  EXPECT_NE(errorOf([] { builtinJob("corner:sped=2"); }).find("unknown key 'sped'"), std::string::npos);
  EXPECT_NE(errorOf([] { loadJob("square", CamConfig{}); }).find("no built-in job named 'square'"), std::string::npos);
  EXPECT_NE(errorOf([] { loadJob("/no/such/job.yaml", CamConfig{}); }).find("cannot open the job file"),
            std::string::npos);
}
