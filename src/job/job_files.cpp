#include "scanhead/job/job_files.hpp"

#include <fstream>
#include <iterator>

#include "scanhead/common/errors.hpp"
#include "scanhead/job/formats/cli_format.hpp"
#include "scanhead/job/formats/job_io.hpp"
#include "scanhead/job/formats/segment_path.hpp"
#include "scanhead/job/generators/builtin_jobs.hpp"

namespace scanhead
{
namespace
{
bool endsWith(const std::string& text, const std::string& suffix)
{
  return text.size() >= suffix.size() && text.compare(text.size() - suffix.size(), suffix.size(), suffix) == 0;
}

std::string firstBytes(const std::string& path, std::size_t count)
{
  std::ifstream in(path, std::ios::binary);
  std::string bytes(count, '\0');
  in.read(&bytes[0], static_cast<std::streamsize>(count));
  bytes.resize(static_cast<std::size_t>(in.gcount()));
  return bytes;
}
}  // namespace

std::string jobFormatsHelp()
{
  std::string help = "a job file (.yaml; .cli ASCII or binary; a segment scan-path file) or a built-in job:";
  for (const auto& line : builtinJobHelp())
    help += "\n  " + line;
  return help;
}

namespace
{
/// \brief The job as the file gives it, layer cam.layer of layered files (CLI, segment: the whole file surveyed in
/// job.file, its bounding box rotated by cam.rotation_deg for cam.centre).
Job readJob(const std::string& argument, const CamConfig& cam)
{
  if (isBuiltinJobName(argument.substr(0, argument.find(':'))))
    return builtinJob(argument, cam.shape_file);
  if (endsWith(argument, ".yaml") || endsWith(argument, ".yml"))
    return loadScanJobFile(argument);
  if (!std::ifstream(argument).good())
  {
    if (argument.find('/') != std::string::npos || argument.find('.') != std::string::npos)
      return loadScanJobFile(argument);  // a path that does not open: "cannot open" names it
    return builtinJob(argument);         // an unknown name fails there, listing the built-in jobs
  }
  const std::string head = firstBytes(argument, 4096);
  if (endsWith(argument, ".cli") || looksLikeCli(head))
  {
    CliReadOptions options;
    options.layer = cam.layer;
    options.box_rotation_deg = cam.rotation_deg;
    options.mark_speed_mps = cam.mark_speed_mps;
    options.jump_speed_mps = cam.jump_speed_mps;
    options.mark_power_w = cam.mark_power_w;
    return readCliFile(argument, options);
  }
  if (looksLikeSegmentPath(head))
  {
    SegmentReadOptions options;
    options.box_rotation_deg = cam.rotation_deg;
    options.unit_m = cam.units == "mm" ? 1e-3 : 1.0;
    options.power_w = cam.mark_power_w;
    options.layer = cam.layer;
    options.power_column = cam.segment_power == "watts"         ? SegmentPower::Watts
                           : cam.segment_power == "coefficient" ? SegmentPower::Coefficient
                                                                : SegmentPower::Auto;
    return readSegmentFile(argument, options);
  }
  return loadScanJobFile(argument);  // YAML without the extension; its errors say what is wrong
}
}  // namespace

Job loadJob(const std::string& argument, const CamConfig& cam)
{
  Job job = readJob(argument, cam);
  if (cam.centre || cam.rotation_deg != 0.0 || cam.offset_m[0] != 0.0 || cam.offset_m[1] != 0.0)
    placeJob(job, placementFor(cam, job));  // cam.centre: the whole file's box, so a build's layers stay aligned
  return job;
}
}  // namespace scanhead
