/// \file thesis_square_job.hpp
/// \brief The THESIS validation job (SPEC §5, THESIS §2.5.1): a grid of 10 mm squares, each marked
/// as inner contour, jump, outer contour, jump, 45° serpentine hatch, with the marking recipes 1–3.
///
/// Layout (THESIS §2.5.1.2, Fig. 2.66–2.67): the first square is the bottom-right one; a "small
/// jump" leads to the square on its left, and so on along the row; after the row's last (leftmost)
/// square a "long jump" leads to the rightmost square of the row above. In a square: the inner
/// contour, a jump, the outer contour, a jump, then the hatch at 45° as a zig-zag from the
/// bottom-right corner to the top-left corner. Contours start and end at their bottom-right corner
/// and run counter-clockwise.
///
/// Defaults not given by the thesis (documented choices): the thesis marks 300 squares on the
/// 350 mm field of the 3-axis head and 100 on the 150 mm field of the 2-axis one, but gives neither
/// the pitch nor the hatch spacing. Default grid 15 rows × 20 columns = 300 squares at a 15 mm pitch
/// (5 mm gap): 295 mm × 220 mm, centred. Hatch spacing 100 µm: the thesis layer times (354.326 s
/// with recipe 1, 263.441 s with recipe 2, §2.6.2) differ by 0.303 s per square, which is
/// L_hatch·(1/1000 − 1/1500) s/mm for L_hatch ≈ 910 mm of hatch per 100 mm² square, i.e. a spacing
/// of about 0.1 mm. Power 200 W on all marks (the thesis gives no power; 200 W at 1 m/s is a usual
/// LPBF line energy of 0.2 J/mm).
#pragma once

#include <vector>

#include "scanhead/job/scan_job.hpp"

namespace scanhead
{
/// \brief Geometry and powers of the square grid (SI units).
struct SquareJobParams
{
  int rows = 15;                     ///< squares per column (rows of the grid), >= 1
  int columns = 20;                  ///< squares per row, >= 1
  double side_m = 0.010;             ///< side of a square = of its outer contour [m]
  double gap_m = 0.005;              ///< gap between neighbouring squares [m] (pitch = side + gap)
  double centre_x_m = 0.0;           ///< centre of the grid [m]
  double centre_y_m = 0.0;           ///< centre of the grid [m]
  double contour_offset_m = 100e-6;  ///< inner contour inset from the outer contour [m]
  double hatch_inset_m = 50e-6;      ///< hatch region inset from the inner contour [m]
  double hatch_spacing_m = 100e-6;   ///< distance between neighbouring hatch lines [m]
  double contour_power_w = 200.0;    ///< laser power on both contours [W]
  double hatch_power_w = 200.0;      ///< laser power on the hatch [W]
  /// false: the serpentine is one MARK polyline whose short connectors run along the hatch
  /// region's edge (zig-zag); true: every hatch line is its own MARK polyline and the connectors
  /// are JUMPs at the recipe's jump_speed_mps.
  bool hatch_jumps_between_lines = false;

  /// \throws ConfigError naming the field (e.g. "square_job.hatch_spacing_m must be > 0 (got 0)")
  void validate() const;

  double pitch_m() const { return side_m + gap_m; }  ///< centre-to-centre distance [m]
};

/// \brief Speeds of a marking recipe [m/s].
struct SquareRecipe
{
  double contour_mark_speed_mps = 1.5;  ///< both contours
  double hatch_mark_speed_mps = 1.0;    ///< the hatch
  double contour_jump_speed_mps = 4.5;  ///< the jump between the inner and the outer contour
  double jump_speed_mps = 6.0;          ///< contour→hatch, hatch→next square, row changes

  /// \throws ConfigError naming the field (prefix "square_recipe.")
  void validate() const;
};

/// \brief Recipes of SPEC §5 / THESIS §2.6 and §3: 1: contour marks 1500 mm/s, hatch 1000 mm/s,
/// jumps 4500 mm/s between the contours and 6000 mm/s otherwise; 2: marks 1500 mm/s, jumps
/// 6000 mm/s; 3: marks 3000 mm/s, jumps 12000 mm/s.
/// \throws ConfigError unless \p recipe is 1, 2 or 3
SquareRecipe thesisRecipe(int recipe);

/// \brief The job with each polyline tagged by its square.
struct SquareJob
{
  Job job;
  /// square index of each polyline (0 = bottom right, then leftwards along the row, then the row
  /// above from the right); the jump leading into a square belongs to that square
  std::vector<int> square_of_polyline;
  int square_count = 0;
};

/// \brief Builds the grid with the speeds of \p recipe. \throws ConfigError on bad parameters
SquareJob makeSquareJob(const SquareJobParams& params, const SquareRecipe& recipe);

/// \brief makeSquareJob(params, thesisRecipe(recipe)).job
Job makeThesisSquareJob(const SquareJobParams& params, int recipe);

/// \brief Ideal time of each square [s] (index = square), on the NC timeline of job_stats.hpp:
/// \f[ t_i = \sum_{k \in \text{square } i} L_k / v_k \f] (the jump into a square counts for it;
/// the job has no implicit jump, so no implicit jump speed is needed).
std::vector<double> squareTimes(const SquareJob& square_job);
}  // namespace scanhead
