/// \file builtin_jobs.hpp
/// \brief Jobs the machine knows without a file: the corner test of the NC paper (SPEC §2).
#pragma once

#include <string>
#include <vector>

#include "scanhead/job/generators/thesis_square_job.hpp"
#include "scanhead/job/scan_job.hpp"

namespace scanhead
{
/// \brief Two MARK segments of \p leg_m meeting at the origin: the first along +x, the second
/// turned by the direction change \p angle_deg (γ; 0 = straight on), both at \p speed_mps.
Job makeCornerJob(double speed_mps, double angle_deg, double leg_m, double power_w);

/// \brief A meander hatch of a square of side \p size_m centred on the origin: MARK lines along x
/// every \p spacing_m, joined by JUMPs.
Job makeHatchJob(double size_m, double spacing_m, double speed_mps, double jump_speed_mps, double power_w);

/// \brief A built-in job by spec "name[:key=value,...]", e.g. "corner:speed=2,angle=108.43".
/// Names: corner (default speed 2 m/s, angle 53.13°, leg 4 mm, power 200 W), hatch, squares.
/// \throws InputError naming the unknown name or key
/// \param[in] shape_file polygon file the generated fills use instead of a square or circle ("": none)
Job builtinJob(const std::string& spec, const std::string& shape_file = "");

/// \brief The THESIS square job of a "squares:..." spec, with the square of each polyline.
SquareJob builtinSquareJob(const std::string& spec);

/// \brief True if \p name (the part of a spec before ':') is a built-in job.
bool isBuiltinJobName(const std::string& name);

/// \brief Names of the built-in jobs with their keys, for help texts.
std::vector<std::string> builtinJobHelp();
}  // namespace scanhead
