/// \file cli_format.hpp
/// \brief Common Layer Interface (CLI) slice files, ASCII and binary, with the CLI+ lines
/// $$POWER, $$SPEED, $$FOCUS: reader to a Job and writers from a Job.
///
/// Format followed (CLI v2.0, hmilch.net/downloads/cli_format.html, cross-checked with two public
/// readers, OpenVectorFormatTools CliFileAccess.cs and the colain crate):
/// \code
/// $$HEADERSTART            // header: always ASCII, one command per line or several per line
/// $$ASCII                  // or $$BINARY (mandatory)
/// $$UNITS/0.005            // mm per coordinate unit (mandatory; 1e-9 <= u <= 1000 accepted here)
/// $$VERSION/200  $$LAYERS/2  $$LABEL/1,part  $$DATE/070493  $$DIMENSION/...  $$ALIGN
/// $$HEADEREND              // binary geometry starts at the very next byte
/// $$GEOMETRYSTART          // ASCII only
/// $$LAYER/0.05             // z [units]; starts layer k (k = 0, 1, ... in file order)
/// $$POWER/200              // CLI+: W, for the following polylines and hatches
/// $$SPEED/800              // CLI+: mm/s, idem
/// $$FOCUS/0.1              // CLI+: mm, parsed and ignored (no focus axis in the model)
/// $$POLYLINE/id,dir,n,p1x,p1y,...,pnx,pny    // dir 0 clockwise, 1 counter-clockwise, 2 open
/// $$HATCHES/id,n,p1sx,p1sy,p1ex,p1ey,...     // n independent segments
/// $$GEOMETRYEND
/// \endcode
/// Comments run from `//` to the next `//` on the same line, or to the end of the line.
/// Parameters are separated by `,` and/or white space, so one command may span several lines.
/// Binary geometry, little-endian, a uint16 command index then its parameters
/// (uint = uint16, int = int32, real = IEEE float32):
/// | index | command | parameters |
/// |---|---|---|
/// | 127 | start layer long   | real z |
/// | 128 | start layer short  | uint z |
/// | 129 | polyline short     | uint id, dir, n; n × (uint x, uint y) |
/// | 130 | polyline long      | int id, dir, n; n × (real x, real y) |
/// | 131 | hatches short      | uint id, n; n × (uint xs, ys, xe, ye) |
/// | 132 | hatches long       | int id, n; n × (real xs, ys, xe, ye) |
/// With $$ALIGN the geometry starts on a 4-byte boundary and the command index and every uint
/// parameter (not the coordinates) are followed by 2 padding bytes (colain's reading of the spec).
#pragma once

#include <string>

#include "scanhead/job/scan_job.hpp"

namespace scanhead
{
/// \brief How a CLI file becomes a Job.
struct CliReadOptions
{
  int layer = 0;                  ///< layer index in file order (not z); -1: all layers, in order
  double mark_speed_mps = 1.0;    ///< mark speed [m/s] until a $$SPEED line
  double jump_speed_mps = 4.5;    ///< speed of the explicit jumps inserted between marks [m/s]
  double mark_power_w = 200.0;    ///< mark power [W] until a $$POWER line
  double box_rotation_deg = 0.0;  ///< the frame of the whole file's bounding box in Job::file (cam.rotation_deg)

  /// \brief \throws ConfigError naming cam.layer, cam.mark_speed_mps, ... and the value
  void validate() const;
};

/// \brief Parses a CLI file (ASCII or binary, told by its header).
///
/// Each polyline becomes a MARK polyline (closed ones keep their closing point as given;
/// polylines of fewer than 2 points are dropped), each hatch a 2-point MARK. Between two
/// consecutive marks whose end and start differ, a JUMP at \p options.jump_speed_mps is inserted.
/// Coordinates: \f[ x_m = x_{units} \cdot u_{mm} \cdot 10^{-3} \f]
/// The whole file is checked and surveyed (Job::file: layers, bounding box, path time per layer),
/// whatever layer is selected; only that layer's polylines are kept. No memory is reserved for a count
/// before checking that the rest of the input can hold it.
/// \param[in] bytes  the whole file
/// \param[in] source file name used in messages and for the job name
/// \throws InputError "source:line: what was expected" (ASCII) or "source: byte offset N: ..."
/// (binary geometry); also when the requested layer does not exist (names how many there are)
/// \throws ConfigError for invalid \p options
Job parseCli(const std::string& bytes, const std::string& source, const CliReadOptions& options);

/// \brief Reads and parses a CLI file. \throws InputError (also when the file cannot be read)
Job readCliFile(const std::string& path, const CliReadOptions& options);

/// \brief The MARK polylines of \p job as one ASCII CLI layer (z = 0); jumps are implicit in CLI.
/// Consecutive 2-point marks become one $$HATCHES command, the others $$POLYLINE with dir 0/1 for
/// closed polylines (by the sign of their area) and 2 for open ones. Numbers are printed in the
/// shortest form that reads back to the same double (std::to_chars).
/// \param[in] units_mm mm per coordinate unit, in [1e-9, 1000] \throws ConfigError otherwise
std::string writeCliAscii(const Job& job, double units_mm);

/// \brief As writeCliAscii, plus CLI+ $$SPEED (mm/s) and $$POWER (W) lines wherever the mark
/// speed or power changes, so speeds and powers read back too.
std::string writeCliAsciiPlus(const Job& job, double units_mm);

/// \brief The MARK polylines of \p job as one binary CLI layer in the long form (commands 127,
/// 130, 132; coordinates as float32: relative resolution 2^-24 ≈ 6e-8 of the value in units).
/// \throws ConfigError for bad \p units_mm; InputError if a coordinate does not fit a float32
std::string writeCliBinary(const Job& job, double units_mm);

/// \brief True if "$$HEADERSTART" occurs in the first 1024 bytes of \p first_bytes.
bool looksLikeCli(const std::string& first_bytes);
}  // namespace scanhead
