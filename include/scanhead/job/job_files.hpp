/// \file job_files.hpp
/// \brief Any job argument to a Job: a built-in spec, a YAML job, a CLI file (ASCII or binary),
/// or a segment scan-path file, detected by extension and content.
#pragma once

#include <string>

#include "scanhead/job/cam_config.hpp"
#include "scanhead/job/job_placement.hpp"
#include "scanhead/job/scan_job.hpp"

namespace scanhead
{
/// \brief The job \p argument names, read with the cam settings where they apply (cam.layer for
/// CLI and segment files, cam.units, cam.segment_power and cam.mark_power_w for segment files, cam
/// speeds and power for CLI marks), then placed on the field by cam.rotation_deg, cam.offset_m and
/// cam.centre (job_placement.hpp; built-in and YAML jobs too).
/// \throws InputError naming the file and what is wrong, or listing the built-in jobs
Job loadJob(const std::string& argument, const CamConfig& cam);

/// \brief Formats the argument may be in, for help texts.
std::string jobFormatsHelp();
}  // namespace scanhead
