/// \file test_cli_format.cpp
/// \brief CLI reader/writer: fixtures (ASCII, binary long/short/aligned), layer selection, CLI+,
/// round trips through both writers, and one error per bad-file category (message text asserted).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>
#include <vector>

#include "fixtures/polyline_fixture.hpp"
#include "scanhead/common/errors.hpp"
#include "scanhead/job/formats/cli_format.hpp"

namespace scanhead
{
namespace
{
const std::string kData = std::string(SCANHEAD_SOURCE_DIR) + "/test/data/cli/";

std::string slurp(const std::string& path)
{
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

CliReadOptions layer(int k)
{
  CliReadOptions o;
  o.layer = k;
  return o;
}

/// \brief The InputError message of parsing \p bytes (fails the test if none is thrown).
std::string errorOf(const std::string& bytes, const CliReadOptions& options = CliReadOptions())
{
  try
  {
    parseCli(bytes, "bad.cli", options);
  }
  catch (const InputError& e)
  {
    return e.what();
  }
  ADD_FAILURE() << "no InputError for:\n" << bytes.substr(0, 200);
  return "";
}

std::vector<const Polyline*> marks(const Job& job)
{
  std::vector<const Polyline*> m;
  for (const Polyline& p : job.polylines)
    if (p.type == PolylineType::Mark)
      m.push_back(&p);
  return m;
}

using test_support::line;

/// \brief Marks of every kind the writers handle: CCW and CW closed polylines, an open one,
/// a run of 2-point marks (hatches), with jumps between them (dropped by the writers).
Job sampleJob()
{
  using V = Eigen::Vector2d;
  Job job;
  job.name = "sample job";
  job.polylines.push_back(
      line(PolylineType::Mark, 1.0, 200.0, {V(0, 0), V(0.01, 0), V(0.01, 0.01), V(0, 0.01), V(0, 0)}));  // CCW
  job.polylines.push_back(line(PolylineType::Jump, 4.5, 0.0, {V(0, 0), V(0.002, 0.002)}));
  job.polylines.push_back(line(PolylineType::Mark, 1.0, 200.0,
                               {V(0.002, 0.002), V(0.002, 0.008), V(0.008, 0.002), V(0.002, 0.002)}));  // CW
  job.polylines.push_back(
      line(PolylineType::Mark, 0.8, 150.0, {V(0.002, 0.002), V(-0.0123456789, 0.00333), V(0.0011, -0.0071)}));  // open
  for (int k = 0; k < 4; ++k)
  {
    const double y = 1e-4 * k;
    const double xs = (k % 2 == 0) ? -0.005 : 0.005;
    job.polylines.push_back(line(PolylineType::Mark, 0.8, 150.0, {V(xs, y), V(-xs, y)}));
  }
  return job;
}

// ---------------------------------------------------------------- fixtures, ASCII

TEST(CliFormat, FullFixtureLayer0GivesMarksJumpsAndCliPlusRecipe)
{
  const Job job = readCliFile(kData + "cli_full.cli", layer(0));
  EXPECT_EQ(job.name, "cli_full_layer0");
  ASSERT_EQ(job.polylines.size(), 6u);  // square, triangle (contiguous), jump, hatch, jump, hatch
  const PolylineType M = PolylineType::Mark, J = PolylineType::Jump;
  const std::vector<PolylineType> types = {M, M, J, M, J, M};
  for (std::size_t i = 0; i < types.size(); ++i)
    EXPECT_EQ(job.polylines[i].type, types[i]) << i;
  // 1 unit = 0.01 mm = 1e-5 m. Tolerance 1e-18 m: a few ulp of 1e-3 m (units × 1e-3 × value).
  const double u = 1e-5;
  const Polyline& square = job.polylines[0];
  ASSERT_EQ(square.points.size(), 5u);  // closing point kept as given
  EXPECT_NEAR(square.points[2].x(), 100 * u, 1e-18);
  EXPECT_NEAR(square.points[2].y(), 100 * u, 1e-18);
  EXPECT_EQ(square.points.front(), square.points.back());
  EXPECT_DOUBLE_EQ(square.speed_mps, 1.0);  // options' defaults before any CLI+ line
  EXPECT_DOUBLE_EQ(square.power_w, 200.0);
  const Polyline& triangle = job.polylines[1];  // was split over three lines
  ASSERT_EQ(triangle.points.size(), 4u);
  EXPECT_NEAR(triangle.points[1].y(), 100 * u, 1e-18);
  EXPECT_NEAR(triangle.points[2].x(), 100 * u, 1e-18);
  const Polyline& jump = job.polylines[2];
  EXPECT_DOUBLE_EQ(jump.speed_mps, 4.5);
  EXPECT_EQ(jump.points.front(), triangle.points.back());
  EXPECT_EQ(jump.points.back(), job.polylines[3].points.front());
  const Polyline& hatch = job.polylines[3];  // after $$POWER/150 $$SPEED/800
  ASSERT_EQ(hatch.points.size(), 2u);
  EXPECT_NEAR(hatch.points[0].y(), 10 * u, 1e-18);
  EXPECT_NEAR(hatch.points[1].x(), 100 * u, 1e-18);
  EXPECT_DOUBLE_EQ(hatch.speed_mps, 0.8);  // 800 mm/s
  EXPECT_DOUBLE_EQ(hatch.power_w, 150.0);
  EXPECT_DOUBLE_EQ(job.polylines[5].speed_mps, 0.8);
}

TEST(CliFormat, LayerSelectionIsByIndexInFileOrder)
{
  const Job l1 = readCliFile(kData + "cli_full.cli", layer(1));
  ASSERT_EQ(l1.polylines.size(), 1u);  // the open line only
  EXPECT_EQ(l1.polylines[0].points.size(), 3u);
  EXPECT_NEAR(l1.polylines[0].points[1].x(), 50e-5, 1e-18);
  // CLI+ state set in layer 0 still holds in layer 1 (file order), $$FOCUS is ignored.
  EXPECT_DOUBLE_EQ(l1.polylines[0].speed_mps, 0.8);
  EXPECT_DOUBLE_EQ(l1.polylines[0].power_w, 150.0);

  const Job all = readCliFile(kData + "cli_full.cli", layer(-1));
  ASSERT_EQ(all.polylines.size(), 8u);  // 6 of layer 0, a jump, the open line
  EXPECT_EQ(all.polylines[6].type, PolylineType::Jump);
  EXPECT_EQ(all.name, "cli_full");

  const std::string msg = errorOf(slurp(kData + "cli_full.cli"), layer(2));
  EXPECT_NE(msg.find("layer 2 requested"), std::string::npos) << msg;
  EXPECT_NE(msg.find("has 2 layers"), std::string::npos) << msg;
}

TEST(CliFormat, MinimalAndHeaderOnlyFixtures)
{
  const Job job = readCliFile(kData + "cli_minimal.cli", CliReadOptions());
  ASSERT_EQ(job.polylines.size(), 1u);
  EXPECT_DOUBLE_EQ(job.polylines[0].points[1].x(), 1e-3);  // 1 unit = 1 mm

  const Job empty = readCliFile(kData + "cli_header_only.cli", layer(-1));
  EXPECT_TRUE(empty.polylines.empty());
  const std::string msg = errorOf(slurp(kData + "cli_header_only.cli"), layer(0));
  EXPECT_NE(msg.find("layer 0 requested, but the file has 0 layers"), std::string::npos) << msg;
}

TEST(CliFormat, CommentsAndSeparators)
{
  const std::string text =
      "// leading comment\n$$HEADERSTART $$ASCII $$UNITS/1 // mm // $$LAYERS/1\n$$HEADEREND\n"
      "$$GEOMETRYSTART\n$$LAYER/0 //z// $$POLYLINE/1,2,3,\t+1,-2 \r\n 3e0 , 4,5,6,\n$$GEOMETRYEND\n";
  const Job job = parseCli(text, "c.cli", CliReadOptions());
  ASSERT_EQ(job.polylines.size(), 1u);
  ASSERT_EQ(job.polylines[0].points.size(), 3u);
  EXPECT_DOUBLE_EQ(job.polylines[0].points[0].x(), 1e-3);
  EXPECT_DOUBLE_EQ(job.polylines[0].points[0].y(), -2e-3);
  EXPECT_DOUBLE_EQ(job.polylines[0].points[1].x(), 3e-3);
  EXPECT_DOUBLE_EQ(job.polylines[0].points[2].y(), 6e-3);
}

// ---------------------------------------------------------------- fixtures, binary

TEST(CliFormat, BinaryLongFormFixture)
{
  const Job job = readCliFile(kData + "cli_minimal_binary.cli", CliReadOptions());
  ASSERT_EQ(job.polylines.size(), 3u);  // polyline, jump, hatch
  EXPECT_EQ(job.polylines[1].type, PolylineType::Jump);
  // units 0.5 mm: 10 units = 5 mm; float32 integers are exact, so only double rounding remains.
  EXPECT_NEAR(job.polylines[0].points[1].x(), 5e-3, 1e-18);
  EXPECT_NEAR(job.polylines[2].points[0].y(), 1e-3, 1e-18);
  EXPECT_NEAR(job.polylines[2].points[1].x(), 5e-3, 1e-18);
}

TEST(CliFormat, BinaryShortFormPackedAndAligned)
{
  for (const char* file : {"cli_short_binary.cli", "cli_short_aligned_binary.cli"})
  {
    const Job job = readCliFile(kData + file, CliReadOptions());
    // closed square (5 points), jump (0,0)->(0,10), hatch, jump, hatch
    ASSERT_EQ(job.polylines.size(), 5u) << file;
    EXPECT_EQ(job.polylines[0].points.size(), 5u) << file;
    EXPECT_NEAR(job.polylines[0].points[2].x(), 100e-5, 1e-18) << file;
    EXPECT_NEAR(job.polylines[2].points[0].y(), 10e-5, 1e-18) << file;
    EXPECT_NEAR(job.polylines[4].points[1].y(), 20e-5, 1e-18) << file;
  }
}

// ---------------------------------------------------------------- round trips

void expectSameMarks(const Job& original, const Job& back, double rel_tol, const std::string& what)
{
  const std::vector<const Polyline*> a = marks(original), b = marks(back);
  ASSERT_EQ(a.size(), b.size()) << what;
  for (std::size_t i = 0; i < a.size(); ++i)
  {
    ASSERT_EQ(a[i]->points.size(), b[i]->points.size()) << what << " mark " << i;
    for (std::size_t j = 0; j < a[i]->points.size(); ++j)
      for (int d = 0; d < 2; ++d)
      {
        const double x = a[i]->points[j][d];
        EXPECT_NEAR(b[i]->points[j][d], x, rel_tol * std::fabs(x) + 1e-300) << what << " mark " << i << " pt " << j;
      }
  }
}

TEST(CliFormat, AsciiRoundTripWithinPrintedResolution)
{
  const Job job = sampleJob();
  for (double units_mm : {1.0, 0.001, 0.005, 0.0137})
  {
    const std::string text = writeCliAscii(job, units_mm);
    const Job back = parseCli(text, "rt.cli", CliReadOptions());
    // Numbers printed shortest-round-trip: the only error is x / u then × u in double, ≤ 2 ulp;
    // tolerance 4 eps relative.
    expectSameMarks(job, back, 4 * std::numeric_limits<double>::epsilon(), "ascii units " + std::to_string(units_mm));
  }
  const std::string text = writeCliAscii(job, 0.001);
  EXPECT_NE(text.find("$$POLYLINE/1,1,5,"), std::string::npos);  // CCW closed square
  EXPECT_NE(text.find("$$POLYLINE/1,0,4,"), std::string::npos);  // CW closed triangle
  EXPECT_NE(text.find("$$POLYLINE/1,2,3,"), std::string::npos);  // open line
  EXPECT_NE(text.find("$$HATCHES/1,4,"), std::string::npos);     // the four 2-point marks
  EXPECT_EQ(text.find("$$SPEED"), std::string::npos);            // plain CLI: no CLI+ lines
  // Jumps come back where mark ends and starts differ, at the read options' jump speed.
  const Job back = parseCli(text, "rt.cli", CliReadOptions());
  ASSERT_EQ(back.polylines.size(), job.polylines.size() + 4);  // + jumps before each of the 4 hatches
  EXPECT_EQ(back.polylines[1].type, PolylineType::Jump);
  EXPECT_EQ(back.polylines[3].type, PolylineType::Mark);  // the open line starts where CW ends
}

TEST(CliFormat, BinaryRoundTripWithinFloat32Resolution)
{
  const Job job = sampleJob();
  for (double units_mm : {1.0, 0.001, 0.0137})
  {
    const std::string bytes = writeCliBinary(job, units_mm);
    const Job back = parseCli(bytes, "rt.cli", CliReadOptions());
    // float32 rounding of the value in units: relative 2^-24 ≈ 6e-8, plus 2 ulp of double.
    expectSameMarks(job, back, 6e-8, "binary units " + std::to_string(units_mm));
  }
}

TEST(CliFormat, AsciiPlusRoundTripKeepsSpeedAndPower)
{
  const Job job = sampleJob();
  const std::string text = writeCliAsciiPlus(job, 0.001);
  EXPECT_NE(text.find("$$SPEED/800\n$$POWER/150"), std::string::npos) << text;
  CliReadOptions o;
  o.mark_speed_mps = 3.0;  // must be overridden by the file's lines
  o.mark_power_w = 10.0;
  const Job back = parseCli(text, "rt.cli", o);
  const std::vector<const Polyline*> a = marks(job), b = marks(back);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i)
  {
    // mm/s ↔ m/s conversion: ≤ 2 ulp; tolerance 4 eps relative.
    EXPECT_NEAR(b[i]->speed_mps, a[i]->speed_mps, 4 * std::numeric_limits<double>::epsilon() * a[i]->speed_mps) << i;
    EXPECT_EQ(b[i]->power_w, a[i]->power_w) << i;
  }
}

// ---------------------------------------------------------------- bad files

struct BadFile
{
  const char* file;
  std::vector<const char*> expected;  ///< substrings of the message
};

TEST(CliFormat, EveryBadFileCategoryNamesTheLineOrOffset)
{
  const std::vector<BadFile> cases = {
      {"cli_invalid_no_header.cli", {"cli_invalid_no_header.cli:1: expected $$HEADERSTART"}},
      {"cli_invalid_no_headerend.cli", {":5: file ends inside the header: expected $$HEADEREND"}},
      {"cli_invalid_non_numeric.cli", {":8: $$POLYLINE: expected a number for y of point 2 of 2, got 'abc'"}},
      {"cli_invalid_units.cli", {":3: $$UNITS: expected mm per coordinate unit in [1e-9, 1000], got '-0.01'"}},
      {"cli_invalid_count.cli", {":8: $$POLYLINE: expected x of point 3 of 3, got '$$LAYER/1'"}},
      {"cli_invalid_huge_count.cli",
       {":7: $$HATCHES: hatch count n = 1000000000000 needs 4000000000000 numbers, more than the remaining"}},
      {"cli_invalid_unknown_command.cli", {":7: unknown command '$$CIRCLE'"}},
      {"cli_invalid_no_geometryend.cli", {":8: file ends inside the geometry section: expected $$GEOMETRYEND"}},
      {"cli_invalid_truncated_binary.cli",
       {": byte offset 73: count n = 2 of points of 'polyline long' needs 16 bytes, but only 6 remain"}},
      {"cli_invalid_huge_count_binary.cli",
       {": byte offset 71: count n = 2147483647 of points of 'polyline long' needs 17179869176 bytes, but only 8 "
        "remain"}},
      {"cli_invalid_unknown_command_binary.cli", {": byte offset 61: unknown command index 200"}},
      // found by fuzz_cli (UBSan: a negative count was cast to an integer for the message)
      {"cli_invalid_fuzz_negative_count.cli",
       {":6: $$POLYLINE: expected point count n >= 0, got -8.8000000073388e+22"}},
  };
  for (const BadFile& c : cases)
  {
    try
    {
      readCliFile(kData + c.file, layer(-1));
      ADD_FAILURE() << c.file << ": no error";
    }
    catch (const InputError& e)
    {
      const std::string msg = e.what();
      EXPECT_EQ(msg.find(kData + c.file), 0u) << msg;  // names the file
      for (const char* s : c.expected)
        EXPECT_NE(msg.find(s), std::string::npos) << c.file << ": " << msg;
    }
  }
}

TEST(CliFormat, EveryFixtureParsesOrIsRejectedCleanly)
{
  // Also the regression inputs from fuzzing: *_invalid_* must give an InputError naming the
  // file, every other file must parse (all layers).
  std::size_t files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(kData))
  {
    const std::string path = entry.path().string();
    const bool invalid = entry.path().filename().string().find("_invalid_") != std::string::npos;
    ++files;
    try
    {
      readCliFile(path, layer(-1));
      EXPECT_FALSE(invalid) << path << ": accepted";
    }
    catch (const InputError& e)
    {
      EXPECT_TRUE(invalid) << e.what();
      EXPECT_EQ(std::string(e.what()).find(path), 0u) << e.what();
    }
  }
  EXPECT_GE(files, 17u);
}

TEST(CliFormat, AbsurdUnitsAndHeaderProblems)
{
  const auto withUnits = [](const std::string& u) {
    return "$$HEADERSTART\n$$ASCII\n$$UNITS/" + u + "\n$$HEADEREND\n";
  };
  for (const char* u : {"0", "-1", "1e-10", "1001", "1e400"})
    EXPECT_NE(errorOf(withUnits(u)).find("bad.cli:3: $$UNITS: expected"), std::string::npos) << u;
  EXPECT_NE(errorOf(withUnits("nan")).find("bad.cli:3: $$UNITS: expected a finite number, got 'nan'"),
            std::string::npos);
  EXPECT_NE(errorOf(withUnits("1mm")).find("bad.cli:3: $$UNITS: expected a number, got '1mm'"), std::string::npos);
  EXPECT_NE(errorOf("$$HEADERSTART\n$$ASCII\n$$HEADEREND\n").find("bad.cli:3: header has no $$UNITS"),
            std::string::npos);
  EXPECT_NE(
      errorOf("$$HEADERSTART\n$$UNITS/1\n$$HEADEREND\n").find("bad.cli:3: header has neither $$ASCII nor $$BINARY"),
      std::string::npos);
  EXPECT_NE(errorOf("$$HEADERSTART\n$$ASCII\nUNITS/1\n").find("bad.cli:3: expected a header command"),
            std::string::npos);
  // $$LAYERS is bounded by what the geometry can hold: 9 bytes per ASCII layer ("$$LAYER/0"), 4 binary,
  // plus one.
  const auto withLayers = [](const std::string& n, int layers) {
    std::string text = "$$HEADERSTART\n$$ASCII\n$$UNITS/1\n$$LAYERS/" + n + "\n$$HEADEREND\n$$GEOMETRYSTART\n";
    for (int k = 0; k < layers; ++k)
      text += "$$LAYER/" + std::to_string(k) + "\n";
    return text + "$$GEOMETRYEND\n";
  };
  EXPECT_NO_THROW(parseCli(withLayers("2", 2), "ok.cli", CliReadOptions()));
  // "\n$$GEOMETRYSTART\n$$LAYER/0\n$$GEOMETRYEND\n": 1 + 16 + 10 + 14 = 41 bytes: at most 1 + 41 / 9 = 5.
  EXPECT_NO_THROW(parseCli(withLayers("5", 1), "ok.cli", CliReadOptions()));
  EXPECT_EQ(errorOf(withLayers("6", 1)),
            "bad.cli:4: $$LAYERS/6 declares more layers than the file can hold (its 41 bytes of geometry hold at "
            "most 5)");
  EXPECT_NE(errorOf(withLayers("1000000000", 1)).find("bad.cli:4: $$LAYERS/1000000000 declares more layers"),
            std::string::npos);
}

TEST(CliFormat, GeometryErrorsNameTheLine)
{
  const std::string head = "$$HEADERSTART\n$$ASCII\n$$UNITS/1\n$$HEADEREND\n$$GEOMETRYSTART\n";
  EXPECT_NE(
      errorOf(head + "$$POLYLINE/1,2,2,0,0,1,1\n$$GEOMETRYEND\n").find("bad.cli:6: $$POLYLINE before any $$LAYER"),
      std::string::npos);
  EXPECT_NE(errorOf(head + "$$LAYER/0\n$$POLYLINE/1,3,2,0,0,1,1\n$$GEOMETRYEND\n")
                .find("bad.cli:7: $$POLYLINE: expected dir 0"),
            std::string::npos);
  EXPECT_NE(errorOf(head + "$$LAYER/0\n$$POLYLINE/1,2,2,0,0,1,1,5\n$$GEOMETRYEND\n")
                .find("bad.cli:7: $$POLYLINE: more parameters"),
            std::string::npos);
  EXPECT_NE(errorOf(head + "$$LAYER/0\n$$POLYLINE/1,2,1.5,0,0\n$$GEOMETRYEND\n")
                .find("expected an integer for point count n"),
            std::string::npos);
  EXPECT_NE(errorOf(head + "$$LAYER/0\n$$SPEED/0\n$$GEOMETRYEND\n").find("bad.cli:7: $$SPEED: expected a speed > 0"),
            std::string::npos);
  EXPECT_NE(errorOf(head + "$$LAYER/0\n$$POWER/-1\n$$GEOMETRYEND\n").find("bad.cli:7: $$POWER: expected a power >= 0"),
            std::string::npos);
  EXPECT_NE(errorOf(head + "$$LAYER/1e999\n$$GEOMETRYEND\n").find("bad.cli:6: $$LAYER: expected a finite number for z"),
            std::string::npos);
  EXPECT_NE(errorOf(head + "$$LAYER/0\n$$POLYLINE/1,2,1,0,,0\n$$GEOMETRYEND\n").find("y of point 1 of 1, got ','"),
            std::string::npos);
  EXPECT_NE(errorOf(head + "$$LAYER/0\n$$GEOMETRYEND\ntrailing\n").find("bad.cli:8: expected the end of the file"),
            std::string::npos);
  EXPECT_NE(errorOf("$$HEADERSTART\n$$ASCII\n$$UNITS/1\n$$HEADEREND\n$$LAYER/0\n")
                .find("bad.cli:5: expected $$GEOMETRYSTART"),
            std::string::npos);
}

TEST(CliFormat, EveryTruncationOfABinaryFileIsAnErrorOrACommandBoundary)
{
  const std::string full = writeCliBinary(sampleJob(), 0.001);
  const std::size_t header = full.find("$$HEADEREND") + 11;
  std::size_t errors = 0, ok = 0;
  for (std::size_t cut = header; cut < full.size(); ++cut)
  {
    try
    {
      parseCli(full.substr(0, cut), "cut.cli", layer(-1));
      ++ok;
    }
    catch (const InputError& e)
    {
      ++errors;
      EXPECT_NE(std::string(e.what()).find("cut.cli: byte offset "), std::string::npos) << e.what();
    }
  }
  // Only the cuts at the 5 command boundaries parse: right after the header (no layer), after
  // the layer command, after each of the 3 polylines (the hatches command is the last one).
  EXPECT_EQ(ok, 5u);
  EXPECT_EQ(errors, full.size() - header - 5);
}

TEST(CliFormat, LooksLikeCliAndOptions)
{
  EXPECT_TRUE(looksLikeCli("$$HEADERSTART\n$$ASCII"));
  EXPECT_TRUE(looksLikeCli("// comment\n  $$HEADERSTART"));
  EXPECT_FALSE(looksLikeCli("name: job\npolylines: []\n"));
  EXPECT_FALSE(looksLikeCli(std::string(2000, ' ') + "$$HEADERSTART"));
  CliReadOptions o;
  o.layer = -2;
  EXPECT_THROW(parseCli("", "x.cli", o), ConfigError);
  try
  {
    o.validate();
  }
  catch (const ConfigError& e)
  {
    EXPECT_NE(std::string(e.what()).find("cam.layer must be >= -1"), std::string::npos) << e.what();
  }
  EXPECT_THROW(writeCliAscii(sampleJob(), 0.0), ConfigError);
  EXPECT_THROW(readCliFile(kData + "no_such_file.cli", CliReadOptions()), InputError);
}
}  // namespace
}  // namespace scanhead
