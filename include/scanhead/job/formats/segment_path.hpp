/// \file segment_path.hpp
/// \brief Reader of the "segment" scan-path format of the thermal codes adamantine and
/// AdditiveFOAM into a Job.
///
/// adamantine's layout: a three-line header, then one row per segment:
/// \code
/// Number of path segments            <- a title (optional here: may be left out)
/// 2                                  <- the number of segments (see below)
/// Mode    x       y     z   pmod    param
/// 1       0.000   0.000  0   0       1e-6
/// 0       0.002   0.000  0   1       0.8
/// 0       0.002   0.0018  0   1       0.8
/// \endcode
/// Row `mode x y z c param`: mode 1 = a spot: the beam stays at (x, y) for param seconds at the
/// power c × nominal power; mode 0 = a line from the previous point to (x, y) at param m/s with
/// the power c × nominal power. Coordinates in m (SegmentReadOptions::unit_m scales them, e.g.
/// 1e-3 for files in mm); speeds always in m/s. The first row must be a spot: it sets the start.
///
/// AdditiveFOAM's layout (detected when the first non-blank line is the column header): only
/// the header `Mode X Y Z Power Param`, then the same rows, except that column 5 is the power in
/// W (SegmentReadOptions::power_w is then not used). 3DThesis and Myna write the same header-only
/// layout with column 5 a 0/1 laser flag (`Mode X(mm) Y(mm) Z(mm) Pmod tParam`, ORNL Peregrine
/// layers), so what column 5 is follows SegmentReadOptions::power_column:
///  * Auto: the column header's fifth word decides when it names the column: starting with
///    "pmod" (any case) a coefficient, with "power" the power in W; any other word, or no fifth
///    word: a coefficient if every row's value is <= 1, else W (a real laser marks at more than
///    1 W, and a coefficient above 1 would overdrive it);
///  * Coefficient, Watts: as named, whatever the header says.
///
/// Layers: z changes between consecutive rows start a new layer (layer k = 0, 1, ... in file
/// order, as adamantine's multi-layer files and CLI's $$LAYER); SegmentReadOptions::layer picks one
/// (-1: all, in order). Rows of the other layers are checked and surveyed all the same (Job::file:
/// layers, bounding box, path time per layer), and they still move
/// the current point (a layer that starts with a line starts where the previous row ended).
///
/// Mapping to the job (work-plane frame, SI):
///  * consecutive mode-0 rows with the same speed and the same power make one polyline, a MARK
///    at c·P if c > 0, a JUMP if c = 0 (P: the nominal power; AdditiveFOAM: c is in W, P = 1);
///  * a mode-1 row with c > 0 and param > 0: a MARK polyline with one point and dwell_s = param
///    at c·P (a spot); the NC reaches it by an implicit jump if it is elsewhere;
///  * a mode-1 row with c = 0 and param > 0: a wait with the laser off, a dwell polyline with
///    power 0 — except before the first polyline, where a wait at the start point only shifts the
///    time origin (the NC is at rest there before t = 0) and is dropped: adamantine's files start
///    with such a 1 µs spot by convention;
///  * a mode-1 row with param = 0: the machine only goes there (the next polyline starts there;
///    the NC inserts the implicit jump at its implicit jump speed). Note adamantine times a
///    mode-1 move to a new point as param seconds; here (as in AdditiveFOAM, where the beam is
///    at a spot's point at once) the move is the NC's implicit jump, then the spot lasts param.
///  * z only separates layers (a scan head marks one plane).
///
/// The count line: adamantine's own example files do not agree with their rows (scan_path_L.txt
/// says 2 for 3 rows, demo_316_short_scan_path.txt 4 for 3, scan_path_layers.txt 2 for 4), so by
/// default the rows are read to the end of the file and the count is only checked to be an
/// integer no larger than the rows the rest of the file could hold (a row is at least 12 bytes);
/// SegmentReadOptions::exact_count requires count = rows. Nothing is ever reserved from the count.
#pragma once

#include <string>

#include "scanhead/job/scan_job.hpp"

namespace scanhead
{
/// \brief What column 5 of a segment file is (see the file comment).
enum class SegmentPower
{
  Auto,
  Coefficient,  ///< × SegmentReadOptions::power_w
  Watts
};

struct SegmentReadOptions
{
  double unit_m = 1.0;       ///< length of one file unit [m]: 1 (m) or 1e-3 (mm); finite, > 0
  double power_w = 200.0;    ///< nominal power [W]: a row's power = coefficient × this; finite, >= 0
  bool exact_count = false;  ///< true: the header's count must equal the number of rows
  SegmentPower power_column = SegmentPower::Auto;
  int layer = -1;                 ///< layer to read (z changes start a new one), in file order; -1: all
  double box_rotation_deg = 0.0;  ///< the frame of the whole file's bounding box in Job::file (cam.rotation_deg)

  /// \brief \throws ConfigError naming segment.unit_m or segment.power_w and the value
  void validate() const;
};

/// \brief Parses a segment scan-path file's text (either layout) into a job (name = the file's stem).
/// \param[in] source the file name (or a description) used in error messages
/// \throws InputError "source:line: field: what is wrong" for a missing or bad header, a wrong
/// count, a wrong number of columns, a non-numeric or non-finite field, an unknown mode, a
/// negative speed, time or power coefficient, a first row that is not a spot, no row at all, or
/// a layer that the file does not have (naming how many it has)
/// \throws ConfigError if \p options is invalid
Job parseSegmentPath(const std::string& text, const std::string& source, const SegmentReadOptions& options);

/// \brief Reads and parses a segment file. \throws InputError (also if it cannot be opened)
Job readSegmentFile(const std::string& path, const SegmentReadOptions& options);

/// \brief True if \p first_bytes (the start of a file) looks like a segment scan path: its first
/// non-empty lines are an integer then a line starting with the word "Mode" (any case),
/// optionally after one title line (adamantine), or its first non-empty line is a 6-word column
/// header starting with "Mode" (AdditiveFOAM).
bool looksLikeSegmentPath(const std::string& first_bytes);
}  // namespace scanhead
