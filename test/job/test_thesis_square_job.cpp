/// \file test_thesis_square_job.cpp
/// \brief The THESIS square job (SPEC §5, THESIS §2.5.1): geometry measured on the output, and
/// per-square times of recipes 1 and 2 against lengths and speeds computed independently here.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "scanhead/common/errors.hpp"
#include "scanhead/job/formats/job_io.hpp"
#include "scanhead/job/generators/thesis_square_job.hpp"
#include "scanhead/job/job_stats.hpp"

namespace scanhead
{
namespace
{
// Coordinates are <= 0.15 m, so double rounding is ~3e-17 m per operation; 1e-12 m is far
// below any geometric error worth seeing (the smallest dimension tested is the 100 µm spacing).
constexpr double kTolM = 1e-12;
// Times are sums of ~300 terms: relative rounding <= 1e-13; 1e-11 relative still catches a
// single wrong speed on a 0.1 mm segment (>= 1e-5 relative).
constexpr double kRelT = 1e-11;

Eigen::Vector2d squareCentre(const Polyline& contour)
{
  return 0.25 * (contour.points[0] + contour.points[1] + contour.points[2] + contour.points[3]);
}

/// Polyline indices of square i in the default (zig-zag) layout: 5 per square + 1 leading jump.
struct SquareIdx
{
  std::size_t inner, contour_jump, outer, to_hatch, hatch;
};
SquareIdx indices(int i)
{
  const std::size_t base = 6 * static_cast<std::size_t>(i);  // square i >= 1: its lead jump is at 6i − 1
  return {base, base + 1, base + 2, base + 3, base + 4};
}
}  // namespace

TEST(ThesisSquareJob, DefaultGridFitsTheFieldAndHasTheThesisStructure)
{
  const SquareJobParams p;
  const SquareJob sj = makeSquareJob(p, thesisRecipe(1));
  EXPECT_EQ(sj.square_count, 300);  // THESIS §2.5.1: 300 squares on the 3-axis head
  EXPECT_EQ(sj.job.polylines.size(), 300u * 5u + 299u);
  EXPECT_EQ(sj.square_of_polyline.size(), sj.job.polylines.size());
  EXPECT_NO_THROW(validateScanJob(sj.job, 0.175));  // the 350 mm field
  // Phase order inside every square: MARK inner, JUMP, MARK outer, JUMP, MARK hatch, then the
  // JUMP into the next square.
  const PolylineType expected[6] = {PolylineType::Mark, PolylineType::Jump, PolylineType::Mark,
                                    PolylineType::Jump, PolylineType::Mark, PolylineType::Jump};
  for (std::size_t k = 0; k < sj.job.polylines.size(); ++k)
  {
    ASSERT_EQ(sj.job.polylines[k].type, expected[k % 6]) << "polyline " << k;
    if (k > 0)  // every polyline starts where the previous one ended: no implicit jump
    {
      ASSERT_LT((sj.job.polylines[k].points.front() - sj.job.polylines[k - 1].points.back()).norm(), kTolM);
    }
  }
  EXPECT_EQ(computeJobStats(sj.job, 1.0).implicit_jump_count, 0u);
}

TEST(ThesisSquareJob, ContoursAreConcentricSquaresOfTheGivenSides)
{
  SquareJobParams p;
  p.rows = 2;
  p.columns = 3;
  p.contour_offset_m = 150e-6;
  const SquareJob sj = makeSquareJob(p, thesisRecipe(1));
  for (int i = 0; i < 6; ++i)
  {
    const SquareIdx ix = indices(i);
    const Polyline& inner = sj.job.polylines[ix.inner];
    const Polyline& outer = sj.job.polylines[ix.outer];
    ASSERT_EQ(inner.points.size(), 5u);
    ASSERT_EQ(outer.points.size(), 5u);
    EXPECT_LT((inner.points.front() - inner.points.back()).norm(), kTolM);  // closed
    const Eigen::Vector2d c = squareCentre(outer);
    EXPECT_LT((squareCentre(inner) - c).norm(), kTolM);
    for (int v = 0; v < 4; ++v)
    {
      EXPECT_NEAR((outer.points[v + 1] - outer.points[v]).norm(), 0.010, kTolM);
      EXPECT_NEAR((inner.points[v + 1] - inner.points[v]).norm(), 0.010 - 2 * 150e-6, kTolM);
      // axis-aligned edges
      const Eigen::Vector2d d = outer.points[v + 1] - outer.points[v];
      EXPECT_LT(std::min(std::abs(d.x()), std::abs(d.y())), kTolM);
    }
    // starts at the bottom-right corner
    EXPECT_LT((outer.points[0] - (c + Eigen::Vector2d(0.005, -0.005))).norm(), kTolM);
    EXPECT_LT((inner.points[0] - (c + Eigen::Vector2d(0.005 - 150e-6, -0.005 + 150e-6))).norm(), kTolM);
  }
}

TEST(ThesisSquareJob, HatchIs45DegreeSerpentineFromBottomRightToTopLeft)
{
  SquareJobParams p;
  p.rows = 1;
  p.columns = 1;
  p.hatch_spacing_m = 80e-6;
  const SquareJob sj = makeSquareJob(p, thesisRecipe(1));
  const Polyline& hatch = sj.job.polylines[indices(0).hatch];
  const Eigen::Vector2d c = squareCentre(sj.job.polylines[indices(0).outer]);
  const double half = 0.005 - p.contour_offset_m - p.hatch_inset_m;  // hatch region half side
  ASSERT_EQ(hatch.points.size() % 2, 0u);
  const std::size_t lines = hatch.points.size() / 2;
  // diagonal / spacing = 9.7 mm·√2 / 0.08 mm = 171.5 → 171 or 172 lines
  EXPECT_NEAR(static_cast<double>(lines), 2 * half * std::sqrt(2.0) / p.hatch_spacing_m, 1.0);
  double previous_c = 1e9;
  for (std::size_t k = 0; k < lines; ++k)
  {
    const Eigen::Vector2d a = hatch.points[2 * k] - c;
    const Eigen::Vector2d b = hatch.points[2 * k + 1] - c;
    const Eigen::Vector2d d = b - a;
    ASSERT_GT(d.norm(), 0.0);
    EXPECT_NEAR(std::abs(d.x()), std::abs(d.y()), kTolM) << "line " << k << " not at 45°";
    EXPECT_GT(d.x() * d.y(), 0.0) << "line " << k << " not along +45°";
    // serpentine: even lines go up-right, odd lines down-left
    EXPECT_EQ(d.x() > 0.0, k % 2 == 0) << "line " << k;
    // both ends on the boundary of the hatch region, none outside it
    for (const Eigen::Vector2d& e : {a, b})
    {
      EXPECT_LE(e.cwiseAbs().maxCoeff(), half + kTolM);
      EXPECT_NEAR(e.cwiseAbs().maxCoeff(), half, kTolM);
    }
    // perpendicular distance between neighbouring lines = the spacing; lines march towards the
    // top-left corner (x − y decreasing)
    const double cval = (a.x() - a.y()) / std::sqrt(2.0);
    if (k > 0)
    {
      EXPECT_NEAR(previous_c - cval, p.hatch_spacing_m, kTolM) << "line " << k;
      // the connector from the previous line stays on/inside the region and is short
      EXPECT_LE((hatch.points[2 * k] - hatch.points[2 * k - 1]).norm(), p.hatch_spacing_m * std::sqrt(2.0) + kTolM);
    }
    previous_c = cval;
  }
  // starts next to the bottom-right corner, ends next to the top-left corner (within ~spacing)
  EXPECT_LT((hatch.points.front() - (c + Eigen::Vector2d(half, -half))).norm(), 2 * p.hatch_spacing_m);
  EXPECT_LT((hatch.points.back() - (c + Eigen::Vector2d(-half, half))).norm(), 2 * p.hatch_spacing_m);
}

TEST(ThesisSquareJob, SquaresRowByRowFromTheBottomRight)
{
  SquareJobParams p;
  p.rows = 3;
  p.columns = 4;
  p.gap_m = 0.004;
  const double pitch = 0.014;
  const SquareJob sj = makeSquareJob(p, thesisRecipe(2));
  double max_small_jump = 0.0, min_long_jump = 1e9;
  Eigen::Vector2d first_centre = Eigen::Vector2d::Zero();
  for (int i = 0; i < 12; ++i)
  {
    const Eigen::Vector2d c = squareCentre(sj.job.polylines[indices(i).outer]);
    if (i == 0)
    {
      first_centre = c;
      // bottom right of a grid centred on the origin
      EXPECT_NEAR(c.x(), 1.5 * pitch, kTolM);
      EXPECT_NEAR(c.y(), -1.0 * pitch, kTolM);
    }
    const int row = i / 4, from_right = i % 4;
    EXPECT_NEAR(c.x(), first_centre.x() - from_right * pitch, kTolM) << "square " << i;
    EXPECT_NEAR(c.y(), first_centre.y() + row * pitch, kTolM) << "square " << i;
    for (std::size_t k = 0; k < sj.job.polylines.size(); ++k)
    {
      if (sj.square_of_polyline[k] == i)
      {
        // every polyline tagged i lies in square i (the leading jump ends there)
        EXPECT_LE((sj.job.polylines[k].points.back() - c).cwiseAbs().maxCoeff(), 0.005 + kTolM);
      }
    }
    if (i > 0)
    {
      const Polyline& lead = sj.job.polylines[indices(i).inner - 1];
      ASSERT_EQ(lead.type, PolylineType::Jump);
      EXPECT_EQ(sj.square_of_polyline[indices(i).inner - 1], i);
      const double len = (lead.points.back() - lead.points.front()).norm();
      (from_right == 0 ? min_long_jump : max_small_jump) =
          from_right == 0 ? std::min(min_long_jump, len) : std::max(max_small_jump, len);
    }
  }
  EXPECT_GT(min_long_jump, 2.0 * max_small_jump);  // "petit jump" along a row, "grand jump" between rows
}

/// Per-square time of a recipe from the geometry, computed here without the generator's code:
/// lengths of the five phases and the leading jump, divided by the recipe's speeds.
double expectedSquareTime(const SquareJobParams& p, const SquareRecipe& r, bool has_lead, double lead_len)
{
  const double off = p.contour_offset_m;
  const double a = p.side_m - 2 * (off + p.hatch_inset_m);  // hatch region side
  const double h = p.hatch_spacing_m;
  const long n = std::lround(a * std::sqrt(2.0) / h);
  // hatch lines x − y = c_k, c_k = ((n−1)/2 − k)·h√2; a line of offset c has length (a − |c|)·√2;
  // connectors run along an edge (|Δc|) or cut a corner (√(c_k² + c_{k+1}²)).
  double hatch_len = 0.0;
  for (long k = 0; k < n; ++k)
  {
    const double ck = (0.5 * (n - 1) - k) * h * std::sqrt(2.0);
    hatch_len += (a - std::abs(ck)) * std::sqrt(2.0);
    if (k + 1 < n)
    {
      const double cn = ck - h * std::sqrt(2.0);
      hatch_len += ((ck >= 0) == (cn >= 0)) ? h * std::sqrt(2.0) : std::hypot(ck, cn);
    }
  }
  const double c0 = 0.5 * (n - 1) * h * std::sqrt(2.0);
  // outer bottom-right corner (s/2, −s/2) to the first hatch point (−a/2 + c0, −a/2)
  const double to_hatch = std::hypot(p.side_m / 2 - (-a / 2 + c0), -p.side_m / 2 + a / 2);
  double t = 4 * (p.side_m - 2 * off) / r.contour_mark_speed_mps + off * std::sqrt(2.0) / r.contour_jump_speed_mps +
             4 * p.side_m / r.contour_mark_speed_mps + to_hatch / r.jump_speed_mps + hatch_len / r.hatch_mark_speed_mps;
  if (has_lead)
  {
    t += lead_len / r.jump_speed_mps;
  }
  return t;
}

/// SPEC §5 recipes written out here (not taken from thesisRecipe): contour mark, hatch mark,
/// jump between contours, other jumps [m/s].
const SquareRecipe kRecipe1{1.5, 1.0, 4.5, 6.0};
const SquareRecipe kRecipe2{1.5, 1.5, 6.0, 6.0};

TEST(ThesisSquareJob, PerSquareTimesOfRecipes1And2MatchTheSpeeds)
{
  SquareJobParams p;
  p.rows = 3;
  p.columns = 5;
  const SquareJob j1 = makeSquareJob(p, thesisRecipe(1));
  const SquareJob j2 = makeSquareJob(p, thesisRecipe(2));
  const std::vector<double> t1 = squareTimes(j1);
  const std::vector<double> t2 = squareTimes(j2);
  ASSERT_EQ(t1.size(), 15u);
  ASSERT_EQ(t2.size(), 15u);
  // The hatch ends near the top-left corner of a square and the next square's inner contour
  // starts at its bottom-right corner: lead jump = centre step + (inner BR − hatch end).
  const double a = p.side_m - 2 * (p.contour_offset_m + p.hatch_inset_m);
  const long n = std::lround(a * std::sqrt(2.0) / p.hatch_spacing_m);
  const double c_last = -0.5 * (n - 1) * p.hatch_spacing_m * std::sqrt(2.0);
  // last line index n−1: even → ends at its top-edge end (a/2 + c, a/2), odd → its left-edge end
  const Eigen::Vector2d hatch_end =
      (n - 1) % 2 == 0 ? Eigen::Vector2d(a / 2 + c_last, a / 2) : Eigen::Vector2d(-a / 2, -a / 2 - c_last);
  const double inner_half = p.side_m / 2 - p.contour_offset_m;
  const Eigen::Vector2d inner_br(inner_half, -inner_half);
  const double pitch = p.pitch_m();
  for (int i = 0; i < 15; ++i)
  {
    const int from_right = i % 5;
    // centre step from the previous square: one pitch right (along a row), or 4 pitches left
    // and one up (row change)
    const Eigen::Vector2d step = from_right == 0 ? Eigen::Vector2d(4 * pitch, pitch) : Eigen::Vector2d(-pitch, 0.0);
    const double lead = (step + inner_br - hatch_end).norm();
    const double e1 = expectedSquareTime(p, kRecipe1, i > 0, lead);
    const double e2 = expectedSquareTime(p, kRecipe2, i > 0, lead);
    EXPECT_NEAR(t1[i], e1, e1 * kRelT) << "square " << i;
    EXPECT_NEAR(t2[i], e2, e2 * kRelT) << "square " << i;
    EXPECT_NEAR(t1[i] / t2[i], e1 / e2, (e1 / e2) * kRelT) << "square " << i;
  }
  // Recipe 2 is faster on the hatch (1.5 vs 1.0 m/s) and the contour jump (6 vs 4.5 m/s), same
  // elsewhere: a square in the middle of a row takes ~1.4x longer with recipe 1.
  EXPECT_GT(t1[1] / t2[1], 1.3);
  EXPECT_LT(t1[1] / t2[1], 1.5);
  // Squares are the whole job.
  double sum1 = 0.0;
  for (double t : t1)
    sum1 += t;
  const double total1 = computeJobStats(j1.job, 1.0).ideal_time_s;
  EXPECT_NEAR(sum1, total1, total1 * kRelT);
}

TEST(ThesisSquareJob, Recipe3IsRecipe2AtTwiceEverySpeed)
{
  SquareJobParams p;
  p.rows = 2;
  p.columns = 3;
  const std::vector<double> t2 = squareTimes(makeSquareJob(p, thesisRecipe(2)));
  const std::vector<double> t3 = squareTimes(makeSquareJob(p, thesisRecipe(3)));
  ASSERT_EQ(t2.size(), t3.size());
  const SquareRecipe r3 = thesisRecipe(3);  // SPEC §5: marks 3000 mm/s, jumps 12000 mm/s
  EXPECT_EQ(r3.contour_mark_speed_mps, 3.0);
  EXPECT_EQ(r3.hatch_mark_speed_mps, 3.0);
  EXPECT_EQ(r3.contour_jump_speed_mps, 12.0);
  EXPECT_EQ(r3.jump_speed_mps, 12.0);
  for (std::size_t i = 0; i < t2.size(); ++i)
  {
    EXPECT_NEAR(t3[i], 0.5 * t2[i], t2[i] * kRelT) << "square " << i;
  }
}

TEST(ThesisSquareJob, SeparateHatchLinesKeepTheGeometry)
{
  SquareJobParams p;
  p.rows = 1;
  p.columns = 2;
  const SquareJob zigzag = makeSquareJob(p, thesisRecipe(2));
  p.hatch_jumps_between_lines = true;
  const SquareJob lines = makeSquareJob(p, thesisRecipe(2));
  const JobStats sz = computeJobStats(zigzag.job, 1.0);
  const JobStats sl = computeJobStats(lines.job, 1.0);
  // Same path, only the connectors turn from MARK to JUMP: total length equal, mark count equal
  // to the number of hatch lines + 8 contour edges per square.
  EXPECT_NEAR(sz.mark_length_m + sz.jump_length_m, sl.mark_length_m + sl.jump_length_m, 1e-12);
  EXPECT_LT(sl.mark_length_m, sz.mark_length_m);
  const std::size_t hatch_lines = zigzag.job.polylines[indices(0).hatch].points.size() / 2;
  EXPECT_EQ(sl.mark_count, 2 * (hatch_lines + 8));
  EXPECT_EQ(sl.mark_polyline_count, 2 * (hatch_lines + 2));
}

TEST(ThesisSquareJob, RejectsBadParameters)
{
  EXPECT_THROW(thesisRecipe(4), ConfigError);
  SquareJobParams p;
  p.hatch_spacing_m = 0.0;
  try
  {
    makeThesisSquareJob(p, 1);
    FAIL() << "no exception";
  }
  catch (const ConfigError& e)
  {
    EXPECT_NE(std::string(e.what()).find("square_job.hatch_spacing_m"), std::string::npos) << e.what();
  }
  p = SquareJobParams();
  p.contour_offset_m = 0.006;
  EXPECT_THROW(makeThesisSquareJob(p, 1), ConfigError);
  p = SquareJobParams();
  p.hatch_spacing_m = 1e-9;  // 1.4e7 lines per square
  EXPECT_THROW(makeThesisSquareJob(p, 1), ConfigError);
  p = SquareJobParams();
  p.rows = 0;
  EXPECT_THROW(makeThesisSquareJob(p, 1), ConfigError);
}
}  // namespace scanhead
