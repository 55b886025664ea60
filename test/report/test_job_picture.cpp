/// \file test_job_picture.cpp
/// \brief Job picture: sizes, aspect, colours measured on the pixels of marks and jumps.
#include <gtest/gtest.h>

#include <cmath>

#include "scanhead/common/errors.hpp"
#include "scanhead/job/generators/thesis_square_job.hpp"
#include "scanhead/report/job_picture.hpp"
#include "scanhead/report/png_writer.hpp"

namespace scanhead
{
namespace
{
Polyline line(PolylineType type, std::vector<Eigen::Vector2d> points)
{
  Polyline p;
  p.type = type;
  p.speed_mps = 1.0;
  p.power_w = type == PolylineType::Mark ? 100.0 : 0.0;
  p.points = std::move(points);
  return p;
}

/// 20 mm mark along x, 10 mm explicit jump up, then a mark starting elsewhere (implicit jump).
Job testJob()
{
  Job job;
  job.name = "picture";
  job.polylines.push_back(line(PolylineType::Mark, {{0.0, 0.0}, {0.02, 0.0}}));
  job.polylines.push_back(line(PolylineType::Jump, {{0.02, 0.0}, {0.02, 0.01}}));
  job.polylines.push_back(line(PolylineType::Mark, {{0.0, 0.005}, {0.005, 0.005}}));
  return job;
}

bool is(const RgbImage& img, int x, int y, const std::array<std::uint8_t, 3>& rgb)
{
  const std::uint8_t* p = img.pixel(x, y);
  return p[0] == rgb[0] && p[1] == rgb[1] && p[2] == rgb[2];
}

const std::array<std::uint8_t, 3> kWhite{{255, 255, 255}};
}  // namespace

TEST(JobPicture, SizeKeepsAspectAndRespectsMaxSide)
{
  const JobPictureOptions o;
  const RgbImage img = renderJobPicture(testJob(), 200);
  const JobPictureFrame f = jobPictureFrame(testJob(), 200, -1);
  EXPECT_EQ(img.width, 200);  // the 20 mm side is the longer one
  EXPECT_EQ(img.width, f.width);
  EXPECT_EQ(img.height, f.height);
  EXPECT_LE(img.height, 200);
  ASSERT_EQ(img.rgb.size(), 3u * 200u * static_cast<std::size_t>(img.height));
  // drawn extents 2:1 within the rounding of one pixel
  const double w = img.width - 1 - 2 * f.margin_px, h = img.height - 1 - 2 * f.margin_px;
  EXPECT_NEAR(w / 2.0, h, 1.0);
  // a tall job: height is the max side
  Job tall = testJob();
  for (Polyline& p : tall.polylines)
    for (Eigen::Vector2d& v : p.points)
      v = Eigen::Vector2d(v.y(), v.x());
  const RgbImage t = renderJobPicture(tall, 333);
  EXPECT_EQ(t.height, 333);
  EXPECT_LT(t.width, 333);
  // margin corners are background
  EXPECT_TRUE(is(img, 0, 0, kWhite));
  EXPECT_TRUE(is(img, img.width - 1, img.height - 1, kWhite));
}

TEST(JobPicture, MarkPixelsAreTheMarkColourAndJumpPixelsTheJumpColour)
{
  const JobPictureOptions o;
  const RgbImage img = renderJobPicture(testJob(), 200);
  const JobPictureFrame f = jobPictureFrame(testJob(), 200, -1);
  // The mark y = 0 lies on the pixel row H − 1 − margin; a pixel centre on the line has
  // distance 0 and full coverage (width 1.5 px), so exactly the mark colour.
  const Eigen::Vector2d a = f.toPixel(Eigen::Vector2d(0.0, 0.0));
  const Eigen::Vector2d b = f.toPixel(Eigen::Vector2d(0.02, 0.0));
  ASSERT_EQ(a.y(), std::round(a.y()));
  const int row = static_cast<int>(a.y());
  for (int x = static_cast<int>(a.x()) + 1; x < static_cast<int>(b.x()); ++x)
  {
    ASSERT_TRUE(is(img, x, row, o.mark_rgb)) << "x " << x;
    ASSERT_TRUE(is(img, x, row - 3, kWhite)) << "x " << x;  // 3 px away: outside the 1.5 px line
  }
  // The explicit jump x = 0.02 m: dashed 4 px on / 3 px off in the jump colour.
  const Eigen::Vector2d j0 = f.toPixel(Eigen::Vector2d(0.02, 0.0));
  const Eigen::Vector2d j1 = f.toPixel(Eigen::Vector2d(0.02, 0.01));
  const int col = static_cast<int>(std::lround(j0.x()));
  int on = 0, off = 0;
  for (int y = static_cast<int>(std::ceil(j1.y())) + 2; y < static_cast<int>(j0.y()) - 2; ++y)
  {
    if (is(img, col, y, o.jump_rgb))
      ++on;
    else if (is(img, col, y, kWhite))
      ++off;
    else
    {
      const std::uint8_t* p = img.pixel(col, y);
      // dash ends are partly covered: grey between the jump colour and white
      EXPECT_TRUE(p[0] == p[1] && p[1] == p[2] && p[0] > o.jump_rgb[0]) << "y " << y;
    }
  }
  EXPECT_GT(on, 10);
  EXPECT_GT(off, 5);
  EXPECT_NEAR(static_cast<double>(on) / (on + off), 4.0 / 7.0, 0.15);  // dash duty 4/7
}

TEST(JobPicture, ImplicitJumpIsDrawnAsAJump)
{
  JobPictureOptions solid;
  solid.jump_dash_px = 0.0;
  const RgbImage img = renderJobPicture(testJob(), 200, solid);
  const JobPictureFrame f = jobPictureFrame(testJob(), 200, -1);
  // midpoint of the implicit jump (0.02, 0.01) → (0, 0.005)
  const Eigen::Vector2d m = f.toPixel(Eigen::Vector2d(0.01, 0.0075));
  const std::uint8_t* p = img.pixel(static_cast<int>(std::lround(m.x())), static_cast<int>(std::lround(m.y())));
  // nearest pixel centre within 0.71 px of the line: coverage >= 0.29 of grey, never blue
  EXPECT_LT(p[0], 255);
  EXPECT_EQ(p[0], p[1]);
  EXPECT_EQ(p[1], p[2]);
  // without jumps that pixel is white
  JobPictureOptions none;
  none.show_jumps = false;
  const RgbImage img2 = renderJobPicture(testJob(), 200, none);
  EXPECT_TRUE(is(img2, static_cast<int>(std::lround(m.x())), static_cast<int>(std::lround(m.y())), kWhite));
}

TEST(JobPicture, StartPointsAndEncodingOfASquareJob)
{
  SquareJobParams p;
  p.rows = 1;
  p.columns = 2;
  const Job job = makeThesisSquareJob(p, 1);
  JobPictureOptions o;
  o.show_start_points = true;
  const RgbImage img = renderJobPicture(job, 400, o);
  EXPECT_EQ(img.width, 400);
  const JobPictureFrame f = jobPictureFrame(job, 400, -1);
  const Eigen::Vector2d s = f.toPixel(job.polylines[0].points[0]);
  EXPECT_TRUE(is(img, static_cast<int>(std::lround(s.x())), static_cast<int>(std::lround(s.y())), o.start_rgb));
  // the hatched squares are mostly blue: count mark-coloured pixels inside square 0
  const Eigen::Vector2d lo = f.toPixel(job.polylines[2].points[2]);  // outer contour top-left
  const Eigen::Vector2d hi = f.toPixel(job.polylines[2].points[0]);  // outer contour bottom-right
  int marked = 0, total = 0;
  for (int y = static_cast<int>(lo.y()) + 3; y < static_cast<int>(hi.y()) - 3; ++y)
    for (int x = static_cast<int>(lo.x()) + 3; x < static_cast<int>(hi.x()) - 3; ++x, ++total)
      marked += img.pixel(x, y)[0] < 255 && img.pixel(x, y)[2] > img.pixel(x, y)[0];
  // 100 µm hatch at 390 px / 25 mm = 1.56 px spacing; a mark reaches 1.25 px either side, so
  // every pixel of the hatched area is touched (blue-ish, not white)
  EXPECT_GT(marked, 0.95 * total);
  const std::vector<std::uint8_t> png = encodePng(img);
  ASSERT_GT(png.size(), 8u);
  EXPECT_EQ(png[1], 'P');
}

TEST(JobPicture, MarkSpotIsADot)
{
  Job job = testJob();
  Polyline spot;
  spot.type = PolylineType::Mark;
  spot.power_w = 100.0;
  spot.dwell_s = 1e-3;
  spot.points = {{0.015, 0.008}};  // away from every line
  job.polylines.push_back(spot);
  const JobPictureOptions o;
  const RgbImage img = renderJobPicture(job, 200);
  const Eigen::Vector2d c = jobPictureFrame(job, 200, -1).toPixel(spot.points[0]);
  const int x = static_cast<int>(std::lround(c.x())), y = static_cast<int>(std::lround(c.y()));
  EXPECT_TRUE(is(img, x, y, o.mark_rgb));
  // radius 1.75 px: a neighbour (centre <= 1.5·√2 = 2.1 px away) is at least partly covered
  EXPECT_FALSE(is(img, x + 1, y, kWhite));
  EXPECT_FALSE(is(img, x, y - 1, kWhite));
  EXPECT_TRUE(is(img, x + 4, y, kWhite));
}

TEST(JobPicture, DegenerateJobsAndBadSizes)
{
  Job single;
  single.polylines.push_back(line(PolylineType::Mark, {{0.01, 0.01}}));
  const RgbImage one = renderJobPicture(single, 64);
  EXPECT_EQ(one.width, 64);
  EXPECT_EQ(one.height, 64);
  const RgbImage empty = renderJobPicture(Job{}, 32);
  EXPECT_EQ(empty.width, 32);
  EXPECT_THROW(renderJobPicture(testJob(), 8), ConfigError);
  EXPECT_THROW(renderJobPicture(testJob(), 100000), ConfigError);
  JobPictureOptions o;
  o.margin_px = 50;
  EXPECT_THROW(renderJobPicture(testJob(), 100, o), ConfigError);
}
}  // namespace scanhead
