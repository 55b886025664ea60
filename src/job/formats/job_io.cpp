#include "scanhead/job/formats/job_io.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "scanhead/common/errors.hpp"
#include "scanhead/common/number_text.hpp"
#include "scanhead/common/yaml_document.hpp"
#include "scanhead/job/job_placement.hpp"

namespace scanhead
{
namespace
{
std::string at(const std::string& source, const YAML::Node& node)
{
  return source + ":" + std::to_string(node.Mark().line + 1);
}

double number(const YAML::Node& node, const std::string& source, const std::string& field)
{
  if (!node.IsScalar())
    throw InputError(at(source, node) + ": " + field + ": expected a number");
  const std::string& text = node.Scalar();
  double value = 0.0;
  const NumberText status = parseNumber(text, value);
  if (status != NumberText::Ok)
    throw InputError(at(source, node) + ": " + field + ": '" + text + "' is not a " +
                     (status == NumberText::NotFinite ? "finite number" : "number"));
  return value;
}

void checkKeys(const YAML::Node& map, const std::vector<std::string>& known, const std::string& source,
               const std::string& where)
{
  for (const auto& item : map)
  {
    if (!item.first.IsScalar())
      throw InputError(at(source, item.first) + ": " + where + "a key is not a name");
    const std::string key = item.first.Scalar();
    if (std::find(known.begin(), known.end(), key) == known.end())
    {
      std::string list;
      for (const auto& k : known)
        list += (list.empty() ? "" : ", ") + k;
      throw InputError(at(source, item.first) + ": " + where + "unknown key '" + key + "' (expected: " + list + ")");
    }
  }
}

Polyline parsePolyline(const YAML::Node& node, const std::string& source, const std::string& field)
{
  if (!node.IsMap())
    throw InputError(at(source, node) + ": " + field + ": expected a map with type, speed, power, points");
  checkKeys(node, {"type", "role", "speed", "power", "points", "dwell"}, source, field + ": ");
  Polyline line;
  const YAML::Node type = node["type"];
  if (!type)
    throw InputError(at(source, node) + ": " + field + ".type: missing (mark or jump)");
  if (type.as<std::string>() == "mark")
    line.type = PolylineType::Mark;
  else if (type.as<std::string>() == "jump")
    line.type = PolylineType::Jump;
  else
    throw InputError(at(source, type) + ": " + field + ".type: '" + type.as<std::string>() + "' is not mark or jump");
  const YAML::Node role = node["role"];
  if (role)
  {
    const std::string text = role.as<std::string>();
    if (text == "contour")
      line.role = PolylineRole::Contour;
    else if (text == "hatch")
      line.role = PolylineRole::Hatch;
    else if (text != "unspecified")
      throw InputError(at(source, role) + ": " + field + ".role: '" + text + "' is not contour, hatch or unspecified");
  }
  const YAML::Node dwell = node["dwell"];
  if (dwell)
  {
    line.dwell_s = number(dwell, source, field + ".dwell");
    if (line.dwell_s < 0.0)
      throw InputError(at(source, dwell) + ": " + field + ".dwell must be >= 0 s (got " +
                       fullPrecisionText(line.dwell_s) + ")");
  }
  const YAML::Node speed = node["speed"];
  if (speed)
    line.speed_mps = number(speed, source, field + ".speed");
  else if (!(line.dwell_s > 0.0))  // a dwell does not move: its speed is optional and unused
    throw InputError(at(source, node) + ": " + field + ".speed: missing (m/s)");
  const YAML::Node power = node["power"];
  if (power)
    line.power_w = number(power, source, field + ".power");
  else if (line.type == PolylineType::Mark)
    throw InputError(at(source, node) + ": " + field + ".power: missing on a mark polyline (W)");
  const YAML::Node points = node["points"];
  if (!points || !points.IsSequence())
    throw InputError(at(source, node) + ": " + field + ".points: expected a list of [x, y] in m");
  for (std::size_t i = 0; i < points.size(); ++i)
  {
    const YAML::Node p = points[i];
    const std::string pf = field + ".points[" + std::to_string(i) + "]";
    if (!p.IsSequence() || p.size() != 2)
      throw InputError(at(source, p) + ": " + pf + ": expected [x, y] in m");
    line.points.emplace_back(number(p[0], source, pf + ".x"), number(p[1], source, pf + ".y"));
  }
  return line;
}

std::string fieldOf(std::size_t polyline)
{
  return "polylines[" + std::to_string(polyline) + "]";
}
}  // namespace

Job parseScanJobYaml(const std::string& yaml_text, const std::string& source)
{
  const YAML::Node root = parseYamlDocument(yaml_text, source, yamlJobLimits());
  if (!root.IsMap())
    throw InputError(source + ":1: expected a map with name and polylines");
  try
  {
    checkKeys(root, {"name", "placement", "polylines"}, source, "");
    Job job;
    job.source = source;
    job.name = root["name"] ? root["name"].as<std::string>() : "job";
    if (const YAML::Node placed = root["placement"])  // written by a placed run: the points are already placed
    {
      if (!placed.IsMap())
        throw InputError(at(source, placed) + ": placement: expected {rotation_deg, offset_m: [x, y], centred}");
      checkKeys(placed, {"rotation_deg", "offset_m", "centred"}, source, "placement: ");
      if (placed["rotation_deg"])
        job.placement.rotation_deg = number(placed["rotation_deg"], source, "placement.rotation_deg");
      if (const YAML::Node o = placed["offset_m"])
      {
        if (!o.IsSequence() || o.size() != 2)
          throw InputError(at(source, o) + ": placement.offset_m: expected [x, y] in m");
        job.placement.offset_m =
            Eigen::Vector2d(number(o[0], source, "placement.offset_m.x"), number(o[1], source, "placement.offset_m.y"));
      }
      if (placed["centred"])
        job.placement.centred = placed["centred"].as<bool>();
    }
    const YAML::Node lines = root["polylines"];
    if (!lines || !lines.IsSequence() || lines.size() == 0)
      throw InputError(at(source, root) + ": polylines: expected a non-empty list");
    for (std::size_t i = 0; i < lines.size(); ++i)
    {
      Polyline line = parsePolyline(lines[i], source, fieldOf(i));
      if (line.dwell_s > 0.0 && line.points.size() != 1)
        throw InputError(at(source, lines[i]) + ": " + fieldOf(i) + ".points: a dwell needs exactly 1 point (got " +
                         std::to_string(line.points.size()) + ")");
      if (!(line.dwell_s > 0.0) && line.points.size() < 2)
        throw InputError(at(source, lines[i]) + ": " + fieldOf(i) + ".points: needs at least 2 points (got " +
                         std::to_string(line.points.size()) + ")");
      job.polylines.push_back(std::move(line));
    }
    return job;
  }
  catch (const YAML::Exception& e)
  {
    throw InputError(source + ":" + std::to_string(e.mark.line + 1) + ": " + e.msg);
  }
}

namespace
{
/// \brief What would bring an out-of-field job onto the field: its extent and the placement that centres it.
std::string placementHint(const Job& job, double field_half_width_m)
{
  Eigen::Vector2d lo, hi;
  if (!rotatedBoundingBox(job, 0.0, lo, hi))
    return "";
  auto mm = [](double m) { return sixDigitText(m * 1e3); };
  const Eigen::Vector2d size = hi - lo, centre = 0.5 * (lo + hi);
  std::string hint =
      ". The job spans x " + mm(lo.x()) + " to " + mm(hi.x()) + " mm, y " + mm(lo.y()) + " to " + mm(hi.y()) + " mm";
  if (size.maxCoeff() > 2.0 * field_half_width_m)
  {
    hint +=
        ": larger than the field; a file in mm read as m? (--set cam.units=mm for segment files; CLI files carry "
        "their own $$UNITS)";
    if (size.maxCoeff() * 1e-3 <= 2.0 * field_half_width_m)
      return hint;
    return hint + ", or a smaller job";
  }
  return hint +
         ". Build files are in the plate's frame: place the job on the field with --set cam.centre=true (its "
         "centre onto the field centre), or --set cam.offset_m=[" +
         sixDigitText(-centre.x()) + "," + sixDigitText(-centre.y()) + "] (and cam.rotation_deg)";
}
}  // namespace

Job loadScanJobFile(const std::string& path)
{
  return parseScanJobYaml(readYamlText(path, yamlJobLimits()), path);
}

void validateScanJob(const Job& job, double field_half_width_m)
{
  if (job.polylines.empty())
    throw InputError(job.source + ": polylines: the job is empty");
  for (std::size_t i = 0; i < job.polylines.size(); ++i)
  {
    const Polyline& line = job.polylines[i];
    const std::string field = job.source + ": " + fieldOf(i);
    if (!std::isfinite(line.dwell_s) || line.dwell_s < 0.0)
      throw InputError(field + ".dwell must be >= 0 s (got " + fullPrecisionText(line.dwell_s) + ")");
    const bool dwell = line.dwell_s > 0.0;
    if (!dwell && (!std::isfinite(line.speed_mps) || line.speed_mps <= 0.0))
      throw InputError(field + ".speed must be > 0 m/s (got " + fullPrecisionText(line.speed_mps) + ")");
    if (!std::isfinite(line.power_w) || line.power_w < 0.0)
      throw InputError(field + ".power must be >= 0 W (got " + fullPrecisionText(line.power_w) + ")");
    if (dwell && line.points.size() != 1)
      throw InputError(field + ".points: a dwell needs exactly 1 point (got " + std::to_string(line.points.size()) +
                       ")");
    if (!dwell && line.points.size() < 2)
      throw InputError(field + ".points: needs at least 2 points (got " + std::to_string(line.points.size()) + ")");
    for (std::size_t k = 0; k < line.points.size(); ++k)
    {
      const Eigen::Vector2d& p = line.points[k];
      const std::string pf = field + ".points[" + std::to_string(k) + "]";
      if (!p.allFinite())
        throw InputError(pf + " is not finite");
      if (std::fabs(p.x()) > field_half_width_m || std::fabs(p.y()) > field_half_width_m)
        throw InputError(pf + " = (" + fullPrecisionText(p.x()) + ", " + fullPrecisionText(p.y()) +
                         ") m lies outside the field (|x|, |y| <= " + fullPrecisionText(field_half_width_m) +
                         " m, optics.field_half_width_m)" + placementHint(job, field_half_width_m));
    }
  }
}

std::string scanJobToYaml(const Job& job)
{
  std::ostringstream out;
  out << "name: " << yamlDoubleQuoted(job.name) << "\n";
  if (job.placement.placed())
    out << "placement: " << job.placement.yaml() << "  # applied: field = R(rotation)·file + offset\n";
  out << "polylines:\n";
  for (const Polyline& line : job.polylines)
  {
    out << "  - type: " << (line.type == PolylineType::Mark ? "mark" : "jump") << "\n";
    if (line.type == PolylineType::Mark && line.role != PolylineRole::Unspecified)
      out << "    role: " << (line.role == PolylineRole::Contour ? "contour" : "hatch") << "\n";
    out << "    speed: " << fullPrecisionText(line.speed_mps) << "\n";
    out << "    power: " << fullPrecisionText(line.power_w) << "\n";
    if (line.dwell_s != 0.0)
      out << "    dwell: " << fullPrecisionText(line.dwell_s) << "\n";
    out << "    points: [";
    for (std::size_t k = 0; k < line.points.size(); ++k)
      out << (k ? ", " : "") << "[" << fullPrecisionText(line.points[k].x()) << ", "
          << fullPrecisionText(line.points[k].y()) << "]";
    out << "]\n";
  }
  return out.str();
}
}  // namespace scanhead
