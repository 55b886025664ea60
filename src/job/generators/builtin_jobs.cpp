#include "scanhead/job/generators/builtin_jobs.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>

#include "scanhead/common/errors.hpp"
#include "scanhead/common/number_text.hpp"
#include "scanhead/job/formats/job_io.hpp"
#include "scanhead/job/generators/scan_generators.hpp"
#include "scanhead/job/generators/shape.hpp"
#include "scanhead/job/generators/thesis_square_job.hpp"

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
    throw InputError("job '" + spec_text + "': unknown key '" + spec.values.begin()->first + "' (known: " + known +
                     ")");
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
  job.source = "built-in corner test of the NC paper: V = " + std::to_string(speed_mps) +
               " m/s, gamma = " + std::to_string(angle_deg) + " deg";
  job.polylines.push_back(line);
  return job;
}

Job makeHatchJob(double size_m, double spacing_m, double speed_mps, double jump_speed_mps, double power_w)
{
  Job job;
  job.name = "hatch";
  job.source = "built-in hatch: square of " + std::to_string(size_m) + " m, lines every " + std::to_string(spacing_m) +
               " m along x";
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
          "hatch[:size=0.005,spacing=0.0001,speed=1,jump_speed=4.5,power=200]  meander hatch of a square",
          "squares[:recipe=1,rows=15,columns=20,side=0.01,gap=0.005,spacing=0.0001,power=200]  the THESIS square job",
          "meander|raster|stripes|chessboard|contours|spiral|hilbert[:size=0.01|radius=R,spacing=1e-4,angle=0,"
          "layer=0,rotation=67,speed=1,jump_speed=4.5,power=200,width=0.005,island=0.005,count=3,offset=1e-4,order=5]"
          "  fills of a square, a circle (radius) or the polygon file cam.shape_file"};
}

namespace
{
const char* const kFillNames[] = {"meander", "raster", "stripes", "chessboard", "contours", "spiral", "hilbert"};

bool isFillName(const std::string& name)
{
  return std::find(std::begin(kFillNames), std::end(kFillNames), name) != std::end(kFillNames);
}

/// A generated fill (scan_generators.hpp) of a square, a circle or the polygon file.
Job fillJob(Spec& spec, const std::string& spec_text, const std::string& shape_file)
{
  const double size = take(spec, "size", 0.01);
  const double radius = take(spec, "radius", 0.0);
  HatchStyle style;
  style.spacing_m = take(spec, "spacing", style.spacing_m);
  const double angle_deg = take(spec, "angle", 0.0);
  const int layer = static_cast<int>(take(spec, "layer", 0.0));
  const double rotation_deg = take(spec, "rotation", 67.0);
  style.angle_rad = layerAngle(angle_deg * M_PI / 180.0, layer, rotation_deg * M_PI / 180.0);
  style.meander = spec.name != "raster";
  style.mark_speed_mps = take(spec, "speed", style.mark_speed_mps);
  style.jump_speed_mps = take(spec, "jump_speed", style.jump_speed_mps);
  style.power_w = take(spec, "power", style.power_w);
  const double width = take(spec, "width", 0.005);
  const double island = take(spec, "island", 0.005);
  const int count = static_cast<int>(take(spec, "count", 3.0));
  const double offset = take(spec, "offset", 1e-4);
  const int order = static_cast<int>(take(spec, "order", 5.0));
  rejectUnknownKeys(spec, spec_text,
                    "size, radius, spacing, angle [deg], layer, rotation [deg], speed, jump_speed, power, width "
                    "(stripes), island (chessboard), count, offset (contours), order (hilbert)");
  const Shape shape = !shape_file.empty() ? readPolygonFile(shape_file)
                      : radius > 0.0      ? makeCircle(Eigen::Vector2d::Zero(), radius, 1e-6)
                                          : makeRectangle(size, size);
  Job job;
  if (spec.name == "meander" || spec.name == "raster")
    job = hatch(shape, style);
  else if (spec.name == "stripes")
    job = stripes(shape, style, width);
  else if (spec.name == "chessboard")
    job = chessboard(shape, style, island);
  else if (spec.name == "contours")
    job = contours(shape, count, offset, style);
  else if (spec.name == "spiral")
    job = spiral(shape, style);
  else
    job = hilbert(shape, order, style);
  job.name = spec.name + "_" + shape.name;
  job.source = "built-in generator (" + spec_text + ")" + (shape_file.empty() ? "" : " on " + shape_file);
  return job;
}
}  // namespace

bool isBuiltinJobName(const std::string& name)
{
  return name == "corner" || name == "hatch" || name == "squares" || isFillName(name);
}

SquareJob builtinSquareJob(const std::string& spec_text)
{
  Spec spec = parseSpec(spec_text);
  if (spec.name != "squares")
    throw InputError("job '" + spec_text + "': not a squares job");
  SquareJobParams params;
  const double recipe = take(spec, "recipe", 1.0);
  params.rows = static_cast<int>(take(spec, "rows", params.rows));
  params.columns = static_cast<int>(take(spec, "columns", params.columns));
  params.side_m = take(spec, "side", params.side_m);
  params.gap_m = take(spec, "gap", params.gap_m);
  params.hatch_spacing_m = take(spec, "spacing", params.hatch_spacing_m);
  params.contour_power_w = params.hatch_power_w = take(spec, "power", params.hatch_power_w);
  rejectUnknownKeys(spec, spec_text, "recipe, rows, columns, side, gap, spacing, power");
  if (recipe != 1.0 && recipe != 2.0 && recipe != 3.0)
    throw InputError("job '" + spec_text + "': recipe must be 1, 2 or 3 (THESIS §2.5.1)");
  params.validate();
  SquareJob squares = makeSquareJob(params, thesisRecipe(static_cast<int>(recipe)));
  squares.job.name = "squares_recipe" + std::to_string(static_cast<int>(recipe));
  squares.job.source = "built-in THESIS square job (" + spec_text + ")";
  return squares;
}

Job builtinJob(const std::string& spec_text, const std::string& shape_file)
{
  Spec spec = parseSpec(spec_text);
  if (isFillName(spec.name))
    return fillJob(spec, spec_text, shape_file);
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
  if (spec.name == "squares")
    return builtinSquareJob(spec_text).job;
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
}  // namespace scanhead
