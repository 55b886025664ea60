/// \file nc_program.hpp
/// \brief What the NC actually runs: the job after the recipe, the speed cap, the mark, jump and
/// polygon delays and skywriting, as one timeline, plus the laser gate on it (SPEC §2.5).
#pragma once

#include <cstddef>
#include <limits>

#include "scanhead/job/path_timeline.hpp"
#include "scanhead/job/recipe.hpp"
#include "scanhead/job/scan_job.hpp"
#include "scanhead/nc/laser_gate.hpp"
#include "scanhead/nc/nc_config.hpp"
#include "scanhead/nc/nc_stats.hpp"

namespace scanhead
{
struct NcProgramOptions
{
  Recipe recipe;                         ///< speeds, powers (if override_job), laser on/off delays
  double implicit_jump_speed_mps = 4.5;  ///< jumps inserted between non-contiguous polylines [m/s]
  double speed_cap_mps = std::numeric_limits<double>::infinity();  ///< every polyline at most this [m/s]
  double mark_delay_s = 0.0;                                       ///< hold after each MARK polyline, laser off [s]
  double jump_delay_s = 0.0;            ///< hold after each jump (explicit or implicit), laser off [s]
  double polygon_delay_s = 0.0;         ///< hold at each corner inside a MARK polyline, laser on [s]
  bool polygon_delay_by_angle = false;  ///< scale the polygon delay by turn angle / 180°
  SkywritingConfig skywriting;

  /// \brief The options of an NcConfig and a recipe.
  static NcProgramOptions from(const NcConfig& nc, const Recipe& recipe);
};

struct NcProgram
{
  PathTimeline timeline;           ///< what X_inter follows
  LaserGate gate;                  ///< laser power on the command timeline
  double laser_on_delay_s = 0.0;   ///< the gate's laser-on delay [s]
  double laser_off_delay_s = 0.0;  ///< the gate's laser-off delay [s]
  NcProgramStats stats;
};

/// \brief Builds the program (segments in order, start times as prefix sums, exact):
///  1. applyRecipe, then every polyline speed min(speed, speed_cap_mps);
///  2. the PathTimeline segments of that job (implicit jumps included);
///  3. skywriting (if enabled), per MARK polyline: before its first point a laser-off run-in
///     along its first direction, after its last a laser-off run-out along its last direction,
///     and at each inner corner turning by more than min_angle_deg: run-out along the incoming
///     direction, a laser-off straight move to the run-in start of the outgoing direction, run-in
///     back to the corner, all at the polyline's speed (run length = run_*_m + run_*_s·v);
///  4. holds (zero-length segments, dwell = false, delay = true): mark delay after the last
///     segment of a MARK polyline (or its run-out), jump delay after each jump, polygon delay at
///     inner corners that are not skywritten (laser on: mark = true).
/// Dwells (spots) are kept as they are (no run-in, run-out or delay of their own).
///
/// Details (documented choices):
///  - the speed cap also applies to the implicit jumps (min(implicit_jump_speed_mps, cap));
///  - a jump followed directly by another jump (e.g. a JUMP polyline that does not end where the
///    next polyline starts, then the implicit jump): a jump delay after each, as an industrial
///    controller waits after each jump command; a JUMP polyline of several points is one jump
///    (one delay after its last move);
///  - an inner corner is a vertex between two consecutive non-zero moves of a MARK polyline with
///    a direction change gamma = angle between the incoming and outgoing directions > 0
///    (collinear vertices get no hold); polygon hold = polygon_delay_s, or
///    polygon_delay_s·gamma/π by angle; it has mark = true, the polyline's power, and speed_mps =
///    the polyline's speed (what power ∝ speed compares to); mark and jump holds: laser off,
///    power 0, speed 0;
///  - skywriting: a corner is skywritten when gamma > min_angle_deg; the jump before a skywritten
///    mark ends at its run-in start and the jump after it starts at its run-out end (their
///    lengths change); where no jump separates a skywritten mark from the previous mark or dwell,
///    a laser-off skywriting move links them at the mark's speed; zero-length moves are skipped;
///    the skywriting moves (mark = false) split the polyline into separate laser bursts;
///  - mark delay after each MARK polyline with at least one move, even if a contiguous mark follows.
/// \throws what PathTimeline throws for bad jobs; ConfigError on bad options (field named:
/// nc.mark_delay_s, nc.jump_delay_s, nc.polygon_delay_s, nc.skywriting.*, recipe.*,
/// nc_program.speed_cap_mps)
NcProgram buildNcProgram(const Job& job, const NcProgramOptions& options);

/// \brief The program of \p segments (a built program's timeline().segments(), e.g. received in a
/// message) with its gate delays and counts: the timeline and gate are rebuilt by the same
/// functions from the same numbers, so the result is bit-identical to the program they came from.
/// \throws what PathTimeline::fromSegments and LaserGate throw
NcProgram ncProgramFromSegments(std::vector<PathSegment> segments, double laser_on_delay_s, double laser_off_delay_s,
                                const NcProgramStats& stats);
}  // namespace scanhead
