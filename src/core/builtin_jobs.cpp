#include "scanhead/core/builtin_jobs.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>

#include "scanhead/core/errors.hpp"
#include "scanhead/core/job_io.hpp"
#include "scanhead/core/number_text.hpp"

namespace scanhead
{
namespace
{
struct Spec
{
  std::string name;
  std::map<std::string, double> values;
};

Spec parseSpec(const std::string& spec)
{
  Spec out;
  const auto colon = spec.find(':');
  out.name = spec.substr(0, colon);
  if (colon == std::string::npos)
    return out;
  std::stringstream rest(spec.substr(colon + 1));
  for (std::string item; std::getline(rest, item, ',');)
  {
    const auto eq = item.find('=');
    if (eq == std::string::npos)
      throw InputError("job '" + spec + "': expected key=value, got '" + item + "'");
    const std::string value = item.substr(eq + 1);
    double number = 0.0;
    if (parseNumber(value, number) != NumberText::Ok)
      throw InputError("job '" + spec + "': " + item.substr(0, eq) + ": '" + value + "' is not a number");
    out.values[item.substr(0, eq)] = number;
  }
  return out;
}

double take(Spec& spec, const std::string& key, double fallback)
{
  const auto it = spec.values.find(key);
  if (it == spec.values.end())
    return fallback;
  const double value = it->second;
  spec.values.erase(it);
  return value;
}
/// Keys left after every take() were not understood.
void rejectUnknownKeys(const Spec& spec, const std::string& spec_text, const char* known)
{
  if (!spec.values.empty())
    throw InputError("job '" + spec_text + "': unknown key '" + spec.values.begin()->first + "' (known: " + known + ")");
}
}  // namespace

Job makeCornerJob(double speed_mps, double angle_deg, double leg_m, double power_w)
{
  const double gamma = angle_deg * M_PI / 180.0;
  Polyline line;
  line.type = PolylineType::Mark;
  line.speed_mps = speed_mps;
  line.power_w = power_w;
  line.points = {Eigen::Vector2d(-leg_m, 0.0), Eigen::Vector2d::Zero(),
                 Eigen::Vector2d(leg_m * std::cos(gamma), leg_m * std::sin(gamma))};
  Job job;
  std::ostringstream name;
  name << "corner_" << angle_deg << "deg_" << speed_mps << "mps";
  job.name = name.str();
  job.source = "built-in corner test of the NC paper: V = " + std::to_string(speed_mps) + " m/s, gamma = " +
               std::to_string(angle_deg) + " deg";
  job.polylines.push_back(line);
  return job;
}

Job makeHatchJob(double size_m, double spacing_m, double speed_mps, double jump_speed_mps, double power_w)
{
  Job job;
  job.name = "hatch";
  job.source = "built-in hatch: square of " + std::to_string(size_m) + " m, lines every " +
               std::to_string(spacing_m) + " m along x";
  const double half = 0.5 * size_m;
  const long lines = std::max(1L, std::lround(size_m / spacing_m) + 1);
  for (long i = 0; i < lines; ++i)
  {
    const double y = -half + static_cast<double>(i) * spacing_m;
    const bool forward = i % 2 == 0;  // meander: every other line backwards
    Polyline mark;
    mark.speed_mps = speed_mps;
    mark.power_w = power_w;
    mark.points = {Eigen::Vector2d(forward ? -half : half, y), Eigen::Vector2d(forward ? half : -half, y)};
    if (i > 0)
    {
      Polyline jump;
      jump.type = PolylineType::Jump;
      jump.speed_mps = jump_speed_mps;
      jump.points = {job.polylines.back().points.back(), mark.points.front()};
      job.polylines.push_back(jump);
    }
    job.polylines.push_back(mark);
  }
  return job;
}

std::vector<std::string> builtinJobHelp()
{
  return {"corner[:speed=2,angle=53.13,leg=0.004,power=200]  two mark segments meeting at the origin",
          "hatch[:size=0.005,spacing=0.0001,speed=1,jump_speed=4.5,power=200]  meander hatch of a square"};
}

Job builtinJob(const std::string& spec_text)
{
  Spec spec = parseSpec(spec_text);
  if (spec.name == "hatch")
  {
    const double size = take(spec, "size", 0.005);
    const double spacing = take(spec, "spacing", 0.0001);
    const double speed = take(spec, "speed", 1.0);
    const double jump_speed = take(spec, "jump_speed", 4.5);
    const double power = take(spec, "power", 200.0);
    rejectUnknownKeys(spec, spec_text, "size, spacing, speed, jump_speed, power");
    if (!(size > 0.0) || !(spacing > 0.0) || size / spacing > 1e6)
      throw InputError("job '" + spec_text + "': size and spacing must be > 0 with at most 1e6 lines");
    return makeHatchJob(size, spacing, speed, jump_speed, power);
  }
  if (spec.name != "corner")
  {
    std::string known;
    for (const auto& help : builtinJobHelp())
      known += "\n  " + help;
    throw InputError("job '" + spec_text + "': no such job file, and no built-in job named '" + spec.name +
                     "'; built-in jobs:" + known);
  }
  const double speed = take(spec, "speed", 2.0);
  const double angle = take(spec, "angle", 53.13);
  const double leg = take(spec, "leg", 0.004);
  const double power = take(spec, "power", 200.0);
  rejectUnknownKeys(spec, spec_text, "speed, angle, leg, power");
  return makeCornerJob(speed, angle, leg, power);
}

Job resolveJob(const std::string& job_argument)
{
  const bool looks_like_path = job_argument.find('/') != std::string::npos ||
                               job_argument.find(".yaml") != std::string::npos ||
                               job_argument.find(".yml") != std::string::npos;
  if (looks_like_path || std::ifstream(job_argument).good())
    return loadScanJobFile(job_argument);
  return builtinJob(job_argument);  // an unknown name fails there, listing the built-in jobs
}
}  // namespace scanhead
