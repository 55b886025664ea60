/// \file cli_writer.cpp
/// \brief Job → CLI (ASCII, ASCII with CLI+ lines, binary long form); marks only.
#include <cctype>
#include <cfloat>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <vector>

#include "scanhead/common/config_check.hpp"
#include "scanhead/common/errors.hpp"
#include "scanhead/job/formats/cli_format.hpp"

namespace scanhead
{
namespace
{
double metresPerUnit(double units_mm)
{
  requireSetting(units_mm >= 1e-9 && units_mm <= 1e3, "units_mm", "in [1e-9, 1000] mm per unit", units_mm);
  return units_mm * 1e-3;  // the reader's expression, so units read back bit-identical
}

void appendNumber(std::string& out, double v)
{
  char buf[32];
  const std::to_chars_result r = std::to_chars(buf, buf + sizeof buf, v);  // shortest round trip
  out.append(buf, r.ptr);
}

/// \brief 0 clockwise, 1 counter-clockwise (closed polylines, by the sign of the shoelace area),
/// 2 open (or closed with zero area).
int direction(const Polyline& p)
{
  if (p.points.size() < 3 || p.points.front() != p.points.back())
    return 2;
  double twice_area = 0.0;
  for (std::size_t i = 0; i + 1 < p.points.size(); ++i)
    twice_area += p.points[i].x() * p.points[i + 1].y() - p.points[i + 1].x() * p.points[i].y();
  return twice_area > 0.0 ? 1 : (twice_area < 0.0 ? 0 : 2);
}

/// \brief A run of marks written as one command: one polyline, or consecutive 2-point marks
/// (with the same speed and power when \p by_recipe) as one hatches command.
struct Group
{
  std::size_t begin = 0;
  std::size_t end = 0;
  bool hatches = false;
};

std::vector<Group> groupMarks(const std::vector<const Polyline*>& marks, bool by_recipe)
{
  std::vector<Group> groups;
  std::size_t i = 0;
  while (i < marks.size())
  {
    Group g;
    g.begin = i;
    g.hatches = marks[i]->points.size() == 2;
    ++i;
    if (g.hatches)
      while (i < marks.size() && marks[i]->points.size() == 2 &&
             (!by_recipe ||
              (marks[i]->speed_mps == marks[g.begin]->speed_mps && marks[i]->power_w == marks[g.begin]->power_w)))
        ++i;
    g.end = i;
    groups.push_back(g);
  }
  return groups;
}

std::vector<const Polyline*> marksOf(const Job& job)
{
  std::vector<const Polyline*> marks;
  for (const Polyline& p : job.polylines)
    if (p.type == PolylineType::Mark && p.points.size() >= 2)
      marks.push_back(&p);
  return marks;
}

/// \brief The job name as a $$LABEL text: letters, digits, '_', '-', '.' only.
std::string label(const std::string& name)
{
  std::string out;
  for (char c : name)
    out += (std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.') ? c : '_';
  return out.empty() ? std::string("job") : out;
}

std::string header(const Job& job, bool binary, double units_mm)
{
  std::string h = "$$HEADERSTART\n";
  h += binary ? "$$BINARY\n" : "$$ASCII\n";
  h += "$$UNITS/";
  appendNumber(h, units_mm);
  h += "\n$$VERSION/200\n$$LABEL/1," + label(job.name) + "\n$$LAYERS/1\n$$HEADEREND";
  return h;
}

double toUnits(double x_m, double m_per_unit, std::size_t polyline)
{
  const double v = x_m / m_per_unit;
  if (!std::isfinite(v))
    throw InputError("writing CLI: mark polyline " + std::to_string(polyline) +
                     ": a coordinate is not finite in the file's units");
  return v;
}

std::string writeAscii(const Job& job, double units_mm, bool plus)
{
  const double m_per_unit = metresPerUnit(units_mm);
  const std::vector<const Polyline*> marks = marksOf(job);
  std::string out = header(job, false, units_mm);
  out += "\n$$GEOMETRYSTART\n$$LAYER/0\n";
  bool have_recipe = false;
  double speed = 0.0;
  double power = 0.0;
  for (const Group& g : groupMarks(marks, plus))
  {
    const Polyline& first = *marks[g.begin];
    if (plus && (!have_recipe || first.speed_mps != speed || first.power_w != power))
    {
      out += "$$SPEED/";
      appendNumber(out, first.speed_mps * 1e3);  // mm/s
      out += "\n$$POWER/";
      appendNumber(out, first.power_w);
      out += '\n';
      have_recipe = true;
      speed = first.speed_mps;
      power = first.power_w;
    }
    if (g.hatches)
    {
      out += "$$HATCHES/1," + std::to_string(g.end - g.begin);
      for (std::size_t k = g.begin; k < g.end; ++k)
        for (const Eigen::Vector2d& p : marks[k]->points)
        {
          out += ',';
          appendNumber(out, toUnits(p.x(), m_per_unit, k));
          out += ',';
          appendNumber(out, toUnits(p.y(), m_per_unit, k));
        }
    }
    else
    {
      out += "$$POLYLINE/1," + std::to_string(direction(first)) + "," + std::to_string(first.points.size());
      for (const Eigen::Vector2d& p : first.points)
      {
        out += ',';
        appendNumber(out, toUnits(p.x(), m_per_unit, g.begin));
        out += ',';
        appendNumber(out, toUnits(p.y(), m_per_unit, g.begin));
      }
    }
    out += '\n';
  }
  out += "$$GEOMETRYEND\n";
  return out;
}

void putU16(std::string& out, std::uint16_t v)
{
  out += static_cast<char>(v & 0xFF);
  out += static_cast<char>(v >> 8);
}

void putU32(std::string& out, std::uint32_t v)
{
  for (int k = 0; k < 4; ++k)
    out += static_cast<char>((v >> (8 * k)) & 0xFF);
}

void putI32(std::string& out, std::int32_t v)
{
  std::uint32_t u;
  std::memcpy(&u, &v, sizeof u);
  putU32(out, u);
}

void putReal(std::string& out, double v, std::size_t polyline)
{
  if (!(std::fabs(v) <= static_cast<double>(FLT_MAX)))
    throw InputError("writing binary CLI: mark polyline " + std::to_string(polyline) +
                     ": a coordinate does not fit a 32-bit real in the file's units");
  const float f = static_cast<float>(v);
  std::uint32_t u;
  std::memcpy(&u, &f, sizeof u);
  putU32(out, u);
}

std::int32_t countOf(std::size_t n, std::size_t polyline)
{
  if (n > static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max()))
    throw InputError("writing binary CLI: mark polyline " + std::to_string(polyline) + ": too many points");
  return static_cast<std::int32_t>(n);
}
}  // namespace

std::string writeCliAscii(const Job& job, double units_mm)
{
  return writeAscii(job, units_mm, false);
}

std::string writeCliAsciiPlus(const Job& job, double units_mm)
{
  return writeAscii(job, units_mm, true);
}

std::string writeCliBinary(const Job& job, double units_mm)
{
  const double m_per_unit = metresPerUnit(units_mm);
  const std::vector<const Polyline*> marks = marksOf(job);
  std::string out = header(job, true, units_mm);
  putU16(out, 127);  // start layer long, z = 0
  putReal(out, 0.0, 0);
  for (const Group& g : groupMarks(marks, false))
  {
    if (g.hatches)
    {
      putU16(out, 132);  // hatches long: int id, int n, n × 4 reals
      putI32(out, 1);
      putI32(out, countOf(g.end - g.begin, g.begin));
      for (std::size_t k = g.begin; k < g.end; ++k)
        for (const Eigen::Vector2d& p : marks[k]->points)
        {
          putReal(out, toUnits(p.x(), m_per_unit, k), k);
          putReal(out, toUnits(p.y(), m_per_unit, k), k);
        }
    }
    else
    {
      const Polyline& line = *marks[g.begin];
      putU16(out, 130);  // polyline long: int id, dir, n, n × 2 reals
      putI32(out, 1);
      putI32(out, direction(line));
      putI32(out, countOf(line.points.size(), g.begin));
      for (const Eigen::Vector2d& p : line.points)
      {
        putReal(out, toUnits(p.x(), m_per_unit, g.begin), g.begin);
        putReal(out, toUnits(p.y(), m_per_unit, g.begin), g.begin);
      }
    }
  }
  return out;
}
}  // namespace scanhead
