/// \file job_io.hpp
/// \brief Scan jobs as YAML files (SI units), with validation that names the file, line and field.
///
/// \code
/// name: corner_53deg
/// polylines:
///   - type: mark          # mark | jump
///     speed: 2.0          # m/s, > 0
///     power: 200.0        # W, >= 0 (optional on jumps)
///     points: [[-0.004, 0.0], [0.0, 0.0], [0.0024, 0.0032]]   # m, work-plane frame, >= 2 points
///   - type: mark          # a spot: the laser stays at one point
///     power: 150.0
///     dwell: 0.001        # s, > 0; then exactly 1 point and speed is optional (unused)
///     points: [[0.001, 0.0]]
/// \endcode
#pragma once

#include <string>

#include "scanhead/job/scan_job.hpp"

namespace scanhead
{
/// \brief Parses a job. \throws InputError "source:line: field: what is wrong"
Job parseScanJobYaml(const std::string& yaml_text, const std::string& source);

/// \brief Reads and parses a job file. \throws InputError
Job loadScanJobFile(const std::string& path);

/// \brief Checks speeds (not on dwells), powers, dwell times (finite, >= 0), finiteness, point
/// counts (>= 2, or exactly 1 for a dwell, dwell_s > 0) and that every point lies in the
/// square field |x|, |y| <= \p field_half_width_m. \throws InputError naming the polyline and point
void validateScanJob(const Job& job, double field_half_width_m);

/// \brief The job as YAML in the format above (full precision; parses back to the same job).
std::string scanJobToYaml(const Job& job);
}  // namespace scanhead
