/// \file test_segment_path.cpp
/// \brief The "segment" scan-path reader (adamantine / AdditiveFOAM format): the real example,
/// the row → polyline mapping, errors naming the file, line and field, detection, robustness, and
/// a spot (dwell) through the NC.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <random>
#include <string>

#include "scanhead/common/errors.hpp"
#include "scanhead/job/formats/job_io.hpp"
#include "scanhead/job/formats/segment_path.hpp"
#include "scanhead/job/path_timeline.hpp"
#include "scanhead/nc/nc_interpolator.hpp"
#include "scanhead/optics/optical_model.hpp"

#ifndef SCANHEAD_SOURCE_DIR
#error "SCANHEAD_SOURCE_DIR must be defined (the package root, for test/data)"
#endif

using namespace scanhead;

namespace
{
const std::string kData = std::string(SCANHEAD_SOURCE_DIR) + "/test/data/";
const std::string kHeader = "Number of path segments\n";

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

/// A file with the three-line header (count \p n) and the given rows.
std::string file(int n, const std::string& rows)
{
  return kHeader + std::to_string(n) + "\nMode x y z pmod param\n" + rows;
}

std::string parseError(const std::string& text, const SegmentReadOptions& options = SegmentReadOptions())
{
  return errorOf([&] { parseSegmentPath(text, "p.txt", options); });
}
}  // namespace

// Acceptance: adamantine's scan_path_L.txt reads as 2 mm, a 90° turn, 1.8 mm, at 0.8 m/s.
// Exact comparisons: the file's decimal numbers are parsed once and used unchanged (unit 1 m).
TEST(SegmentPath, ReadsTheAdamantineLExample)
{
  SegmentReadOptions options;
  options.power_w = 250.0;
  const Job job = readSegmentFile(kData + "segment_path_L.txt", options);
  EXPECT_EQ(job.name, "segment_path_L");
  EXPECT_EQ(job.source, kData + "segment_path_L.txt");
  // the leading 1 µs laser-off spot only sets the start point: one MARK polyline of 3 points
  ASSERT_EQ(job.polylines.size(), 1u);
  const Polyline& mark = job.polylines[0];
  EXPECT_EQ(mark.type, PolylineType::Mark);
  EXPECT_EQ(mark.speed_mps, 0.8);
  EXPECT_EQ(mark.power_w, 250.0);  // coefficient 1 × nominal power
  EXPECT_EQ(mark.dwell_s, 0.0);
  ASSERT_EQ(mark.points.size(), 3u);
  EXPECT_EQ(mark.points[0], Eigen::Vector2d(0.0, 0.0));
  EXPECT_EQ(mark.points[1], Eigen::Vector2d(0.002, 0.0));
  EXPECT_EQ(mark.points[2], Eigen::Vector2d(0.002, 0.0018));
  const Eigen::Vector2d leg1 = mark.points[1] - mark.points[0];
  const Eigen::Vector2d leg2 = mark.points[2] - mark.points[1];
  EXPECT_NEAR(leg1.norm(), 2e-3, 1e-18);    // 2 mm; 1e-18: one rounding of 0.0018 − 0
  EXPECT_NEAR(leg2.norm(), 1.8e-3, 1e-18);  // 1.8 mm
  EXPECT_EQ(leg1.dot(leg2), 0.0);           // 90°: exactly orthogonal
  const auto corners = findCorners(job, 0.1, 4.5);
  ASSERT_EQ(corners.size(), 1u);
  EXPECT_NEAR(corners[0].angle_rad, M_PI / 2, 1e-15);
  EXPECT_EQ(corners[0].point, Eigen::Vector2d(0.002, 0.0));
  // the ideal time: 3.8 mm at 0.8 m/s = 4.75 ms (tolerance: two roundings, 1e-18 s)
  EXPECT_NEAR(PathTimeline(job, 4.5).duration(), 3.8e-3 / 0.8, 1e-18);
  EXPECT_NO_THROW(validateScanJob(job, 0.175));
  // exact_count: its header says 2 segments for 3 rows
  options.exact_count = true;
  EXPECT_NE(errorOf([&] {
              readSegmentFile(kData + "segment_path_L.txt", options);
            }).find("segment_path_L.txt:2: count: the header says 2 segments but the file has 3 rows"),
            std::string::npos);
}

// Units: coordinates scale by unit_m (adamantine's scan_path_units.txt: mm), speeds stay in m/s;
// z is ignored; the title line may be left out; CRLF line ends and blank lines are accepted.
TEST(SegmentPath, UnitsTitleAndLineEnds)
{
  SegmentReadOptions mm;
  mm.unit_m = 1e-3;
  const Job job = parseSegmentPath("2\r\nMode x y z pmod param\r\n1 0 100 100 0 1e-6\r\n\r\n0 2 100 100 1 0.8\r\n\n",
                                   "units.txt", mm);
  ASSERT_EQ(job.polylines.size(), 1u);
  ASSERT_EQ(job.polylines[0].points.size(), 2u);
  EXPECT_EQ(job.polylines[0].points[0], Eigen::Vector2d(0.0, 100 * 1e-3));
  EXPECT_EQ(job.polylines[0].points[1], Eigen::Vector2d(2 * 1e-3, 100 * 1e-3));
  EXPECT_EQ(job.polylines[0].speed_mps, 0.8);
  EXPECT_EQ(job.polylines[0].power_w, 200.0);  // default nominal power, coefficient 1
}

// AdditiveFOAM's layout: only the column header, power in W (the nominal power is not used),
// a zero-time first spot (its tutorials' convention).
TEST(SegmentPath, AdditiveFoamLayoutHasPowerInWatts)
{
  SegmentReadOptions options;
  options.power_w = 1000.0;  // not used: the file gives watts
  const std::string text =
      "Mode    X       Y       Z       Power       Param\n"
      "1       0.000   0.000   0       0           0\n"
      "0       0.002   0.000   0       195         0.8\n"
      "1       0.002   0.000   0       50          2e-4\n";
  EXPECT_TRUE(looksLikeSegmentPath(text));
  const Job job = parseSegmentPath(text, "scanPath", options);
  ASSERT_EQ(job.polylines.size(), 2u);
  EXPECT_EQ(job.polylines[0].power_w, 195.0);
  EXPECT_EQ(job.polylines[0].speed_mps, 0.8);
  EXPECT_EQ(job.polylines[0].points[1], Eigen::Vector2d(0.002, 0.0));
  EXPECT_EQ(job.polylines[1].power_w, 50.0);
  EXPECT_EQ(job.polylines[1].dwell_s, 2e-4);
  EXPECT_NE(parseError("Mode X Y Z Power Param\n1 0 0 0 -5 0\n").find("p.txt:2: power: must be >= 0 (got -5)"),
            std::string::npos);
  EXPECT_NE(parseError("Mode X Y Z Power Param\n1 0 0 0 0\n")
                .find("p.txt:2: row: expected 6 columns (mode x y z power param)"),
            std::string::npos);
  EXPECT_NE(parseError("Mode X Y Z Power Param\n").find("p.txt:2: row: no segment row after the header"),
            std::string::npos);
}

// Row → polyline mapping: merging of equal lines, power coefficients, jumps, spots with the laser
// on (a dwell), waits with the laser off (a power-0 dwell), moves without time (no polyline).
TEST(SegmentPath, MapsRowsToPolylines)
{
  SegmentReadOptions options;
  options.power_w = 100.0;
  const std::string rows =
      "1  0     0     0  0    1e-6\n"   // start point (wait dropped)
      "0  1e-3  0     0  1    1.0\n"    // mark 100 W at 1 m/s
      "0  2e-3  0     0  1    1.0\n"    //   same speed and power: same polyline
      "0  2e-3  1e-3  0  0.5  1.0\n"    // 50 W: a new polyline
      "0  0     1e-3  0  0    3.0\n"    // jump at 3 m/s
      "0  0     2e-3  0  0    3.0\n"    //   merged into the jump
      "1  0     2e-3  0  1.2  1e-3\n"   // spot: 1 ms at 120 W
      "1  0     2e-3  0  0    2e-3\n"   // wait 2 ms, laser off
      "1  4e-3  4e-3  0  0    0\n"      // go there (no time, no polyline)
      "0  5e-3  4e-3  0  1    2.0\n"    // mark from (4, 4) mm
      "1  -1e-3 0     0  2    5e-4\n";  // spot elsewhere: reached by an implicit jump
  const Job job = parseSegmentPath(file(11, rows), "map.txt", options);
  ASSERT_EQ(job.polylines.size(), 7u);
  const auto& p = job.polylines;
  EXPECT_EQ(p[0].type, PolylineType::Mark);
  EXPECT_EQ(p[0].power_w, 100.0);
  EXPECT_EQ(p[0].speed_mps, 1.0);
  ASSERT_EQ(p[0].points.size(), 3u);
  EXPECT_EQ(p[0].points[2], Eigen::Vector2d(2e-3, 0.0));
  EXPECT_EQ(p[1].power_w, 50.0);
  ASSERT_EQ(p[1].points.size(), 2u);
  EXPECT_EQ(p[1].points[0], Eigen::Vector2d(2e-3, 0.0));  // starts where the previous ended
  EXPECT_EQ(p[2].type, PolylineType::Jump);
  EXPECT_EQ(p[2].speed_mps, 3.0);
  EXPECT_EQ(p[2].power_w, 0.0);
  ASSERT_EQ(p[2].points.size(), 3u);
  EXPECT_EQ(p[3].type, PolylineType::Mark);
  EXPECT_EQ(p[3].dwell_s, 1e-3);
  EXPECT_EQ(p[3].power_w, 120.0);
  ASSERT_EQ(p[3].points.size(), 1u);
  EXPECT_EQ(p[3].points[0], Eigen::Vector2d(0.0, 2e-3));
  EXPECT_EQ(p[4].dwell_s, 2e-3);
  EXPECT_EQ(p[4].power_w, 0.0);
  ASSERT_EQ(p[5].points.size(), 2u);
  EXPECT_EQ(p[5].points[0], Eigen::Vector2d(4e-3, 4e-3));
  EXPECT_EQ(p[5].speed_mps, 2.0);
  EXPECT_EQ(p[6].dwell_s, 5e-4);
  EXPECT_EQ(p[6].power_w, 200.0);
  EXPECT_NO_THROW(validateScanJob(job, 0.175));

  // The timeline: Σ L/v + Σ dwell + the two implicit jumps (to (4, 4) mm and to (−1, 0) mm).
  // Tolerance 1e-17 s: ~12 terms of ~1e-3 s, each rounded at 1.1e-16 relative.
  const double jump_speed = 4.5;
  const double expected = 2e-3 / 1.0 + 1e-3 / 1.0 + (2e-3 + 1e-3) / 3.0 + 1e-3 + 2e-3 +
                          Eigen::Vector2d(4e-3, 2e-3).norm() / jump_speed + 1e-3 / 2.0 +
                          Eigen::Vector2d(6e-3, 4e-3).norm() / jump_speed + 5e-4;
  EXPECT_NEAR(PathTimeline(job, jump_speed).duration(), expected, 1e-17);
  // round trip through the project's YAML, dwells included
  const Job back = parseScanJobYaml(scanJobToYaml(job), "rt.yaml");
  ASSERT_EQ(back.polylines.size(), job.polylines.size());
  for (std::size_t i = 0; i < job.polylines.size(); ++i)
  {
    EXPECT_EQ(back.polylines[i].dwell_s, job.polylines[i].dwell_s);
    EXPECT_EQ(back.polylines[i].points, job.polylines[i].points);
  }
}

// Every bad file gives an InputError naming the file, the line and the field.
TEST(SegmentPath, ErrorsNameFileLineAndField)
{
  const std::string start = "1 0 0 0 0 1e-6\n";
  auto has = [](const std::string& message, const std::string& expected) {
    EXPECT_NE(message.find(expected), std::string::npos) << "got: '" << message << "'";
  };
  has(parseError(""), "p.txt:1: header: the file is empty");
  has(parseError("Number of path segments\n"), "p.txt:2: count: missing");
  has(parseError("Number of path segments\ntwo\nMode\n"), "p.txt:2: count: 'two' is not a number of segments");
  has(parseError("Number of path segments\n-3\nMode\n"), "p.txt:2: count: '-3' is not a number of segments");
  has(parseError("Number of path segments\n1\n"), "p.txt:3: header: missing the column header");
  has(parseError("Number of path segments\n1\nx y z\n" + start), "p.txt:3: header: 'x y z' is not the column header");
  has(parseError(file(0, "")), "p.txt:4: row: no segment row after the header");
  // huge count: refused against the bytes that follow, before anything is read or reserved
  has(parseError(file(1000000000, start)), "p.txt:2: count: 1000000000 segments cannot fit in the 15 bytes");
  has(parseError(kHeader + "123456789012345678901234\nMode\n" + start), "p.txt:2: count: '1234567890123456789012");
  has(parseError(file(0, "1 0 0 0 0\n")),
      "p.txt:4: row: expected 6 columns (mode x y z power_coefficient param), got 5");
  has(parseError(file(1, "1 0 0 0 0 1 7\n")), "p.txt:4: row: expected 6 columns");
  has(parseError(file(2, start + "0 1e-3 abc 0 1 1\n")), "p.txt:5: y: 'abc' is not a number");
  has(parseError(file(2, start + "0 1e-3 0 0 nan 1\n")), "p.txt:5: power_coefficient: 'nan' is not a finite number");
  has(parseError(file(2, start + "0 1e-3 0 0 1 1e999\n")), "p.txt:5: param: '1e999' is not a finite number");
  has(parseError(file(2, start + "2 1e-3 0 0 1 1\n")),
      "p.txt:5: mode: 2 is not a known mode (expected 0: line, 1: spot)");
  has(parseError(file(2, start + "0 1e-3 0 0 1 -0.8\n")), "p.txt:5: param: a line's speed must be > 0 m/s (got -0.8)");
  has(parseError(file(2, start + "0 1e-3 0 0 1 0\n")), "p.txt:5: param: a line's speed must be > 0 m/s (got 0)");
  has(parseError(file(2, start + "1 1e-3 0 0 1 -1e-3\n")), "p.txt:5: param: a spot's dwell time must be >= 0 s");
  has(parseError(file(2, start + "0 1e-3 0 0 -1 1\n")), "p.txt:5: power_coefficient: must be >= 0 (got -1)");
  has(parseError(file(1, "0 1e-3 0 0 1 1\n")), "p.txt:4: mode: the first row must be a spot (mode 1)");
  // blank lines count in the line numbers
  has(parseError(file(2, start + "\n\n0 1e-3 0 0 1 x\n")), "p.txt:7: param: 'x' is not a number");
  // a scaled coordinate that overflows
  SegmentReadOptions huge;
  huge.unit_m = 1e300;
  has(parseError(file(1, "1 1e10 0 0 1 1\n"), huge), "p.txt:4: x: 10000000000 × unit");
  // options
  SegmentReadOptions bad;
  bad.unit_m = 0.0;
  EXPECT_THROW(parseSegmentPath(file(1, start), "p.txt", bad), ConfigError);
  bad.unit_m = 1.0;
  bad.power_w = -1.0;
  EXPECT_THROW(parseSegmentPath(file(1, start), "p.txt", bad), ConfigError);
  has(errorOf([] { readSegmentFile(kData + "no_such_file.txt", SegmentReadOptions()); }),
      "no_such_file.txt: cannot open the segment scan-path file");
}

// Detection on the first bytes of a file (possibly cut mid-line).
TEST(SegmentPath, LooksLikeSegmentPath)
{
  const std::string l_file = kHeader + "2\nMode    x       y     z   pmod    param\n1 0 0 0 0 1e-6\n";
  EXPECT_TRUE(looksLikeSegmentPath(l_file));
  EXPECT_TRUE(looksLikeSegmentPath(l_file.substr(0, kHeader.size() + 6)));  // cut after "Mode"
  EXPECT_TRUE(looksLikeSegmentPath("\n  3  \r\nmode x y z c p\n"));
  EXPECT_FALSE(looksLikeSegmentPath(l_file.substr(0, kHeader.size() + 4)));  // "Mo": not enough to tell
  EXPECT_FALSE(looksLikeSegmentPath(""));
  EXPECT_FALSE(looksLikeSegmentPath("name: t\npolylines:\n  - type: mark\n"));
  EXPECT_FALSE(looksLikeSegmentPath("$$HEADERSTART\n$$ASCII\n$$UNITS/1\n"));
  EXPECT_FALSE(looksLikeSegmentPath("Number of path segments\nMode x y z\n"));  // no count
  EXPECT_FALSE(looksLikeSegmentPath(std::string("\x00\x01\x02Mode\n", 8)));
  EXPECT_FALSE(looksLikeSegmentPath("Modes x y z pmod param\n1 0 0 0 0 0\n"));  // "Modes" is not "Mode"
  EXPECT_FALSE(looksLikeSegmentPath("Mode x y\n1 0 0\n"));                      // a header of 3 words
}

// Robustness: 3000 random byte mutations of the L example (seeded) either parse to a job or
// throw InputError; nothing else (no crash, no other exception). The fuzz target goes further.
TEST(SegmentPath, MutatedFilesOnlyThrowInputError)
{
  const std::string base = kHeader +
                           "2\nMode    x       y     z   pmod    param\n"
                           "1       0.000   0.000  0   0       1e-6\n"
                           "0       0.002   0.000  0   1       0.8\n"
                           "0       0.002   0.0018  0   1       0.8\n";
  std::mt19937 rng(12345);
  const char alphabet[] = "0123456789 .-+eE\n\tMmx";
  int parsed = 0;
  for (int trial = 0; trial < 3000; ++trial)
  {
    std::string text = base;
    const int edits = 1 + static_cast<int>(rng() % 4);
    for (int e = 0; e < edits; ++e)
    {
      const std::size_t at = rng() % text.size();
      switch (rng() % 3)
      {
        case 0:
          text[at] = alphabet[rng() % (sizeof alphabet - 1)];
          break;
        case 1:
          text.erase(at, 1 + rng() % 8);
          break;
        default:
          text.insert(at, 1, static_cast<char>(rng() % 256));
          break;
      }
      if (text.empty())
        text = "\n";
    }
    try
    {
      const Job job = parseSegmentPath(text, "fuzz", SegmentReadOptions());
      ++parsed;
      for (const Polyline& p : job.polylines)
        for (const Eigen::Vector2d& q : p.points)
          ASSERT_TRUE(q.allFinite());
    }
    catch (const InputError&)
    {
    }
  }
  EXPECT_GT(parsed, 10);  // some mutations stay valid (e.g. a changed digit)
}

// A spot through the NC: a 1 ms dwell at 100 W (segment row "1 x y z 0.5 1e-3", nominal 200 W)
// between two lines. The laser is on for 1 ms ± 1 sample at 100 W during the spot, the path
// point (X_inter) stays at the spot while it lasts, and the path duration includes the dwell.
TEST(SegmentPath, SpotDwellThroughTheNc)
{
  const OpticalModel optics(geometryFromUrdfFile(std::string(SCANHEAD_SOURCE_DIR) + "/urdf/scanhead.urdf"),
                            OpticsConfig());
  const std::string rows =
      "1 -0.002 0 0 0 1e-6\n"
      "0 -0.001 0 0 0 2.0\n"     // a jump (laser off)
      "1 -0.001 0 0 0.5 1e-3\n"  // the spot: 1 ms at 0.5 × 200 W
      "0 0.001 0 0 0 2.0\n";     // a jump away
  const Job job = parseSegmentPath(file(4, rows), "spot.txt", SegmentReadOptions());
  ASSERT_EQ(job.polylines.size(), 3u);
  ASSERT_EQ(job.polylines[1].dwell_s, 1e-3);
  validateScanJob(job, 0.175);

  NcConfig config;
  config.debug = true;
  NcInterpolator nc(config, optics);
  nc.start(job);
  // path: 1 mm jump at 2 m/s, 1 ms dwell, 2 mm jump at 2 m/s (tolerance: a few roundings)
  EXPECT_NEAR(nc.pathDuration(), 0.5e-3 + 1e-3 + 1e-3, 1e-15);
  std::size_t on = 0;
  std::size_t at_spot = 0;
  const double t_spot = 0.5e-3;
  const double delay = config.filterDelay();
  while (!nc.done())
  {
    const NcOutput out = nc.process(777);
    for (std::size_t i = 0; i < out.laser.samples.size(); ++i)
    {
      const double t = static_cast<double>(out.laser.first_index + i) * config.period_s;
      const double power = out.laser.samples[i].power_w;
      if (power > 0.0)
      {
        ++on;
        EXPECT_EQ(power, 100.0);
        // the laser is aligned on the filtered setpoint: it is on during [t_spot, t_spot + 1 ms) + delay
        EXPECT_GE(t - delay, t_spot - 1e-12);
        EXPECT_LT(t - delay, t_spot + 1e-3 + 1e-12);
      }
      if (t >= t_spot && t < t_spot + 1e-3)
      {
        ++at_spot;
        EXPECT_EQ(out.debug.samples[i].x_inter, Eigen::Vector2d(-0.001, 0.0)) << "t = " << t;
      }
    }
  }
  const double samples_in_dwell = 1e-3 / config.period_s;
  EXPECT_NEAR(static_cast<double>(on), samples_in_dwell, 1.0);  // ± 1 sample: the grid vs the ends
  EXPECT_NEAR(static_cast<double>(at_spot), samples_in_dwell, 1.0);
}
