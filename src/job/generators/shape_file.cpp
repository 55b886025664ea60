// Polygon text files: "x y" per line in metres, '#' comments, blank lines between rings.
#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

#include "scanhead/common/errors.hpp"
#include "scanhead/common/number_text.hpp"
#include "scanhead/job/generators/shape.hpp"

namespace scanhead
{
namespace
{
/// Ring being read, with the line numbers that name it in errors.
struct RingText
{
  Ring points;
  std::size_t first_line = 0;
  std::size_t last_line = 0;
};

std::string quoted(const std::string& text)
{
  constexpr std::size_t kMax = 60;
  std::string shown = text.size() > kMax ? text.substr(0, kMax) + "..." : text;
  for (char& c : shown)
    if (static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) >= 0x7f)
      c = '?';
  return "'" + shown + "'";
}

std::string fileStem(const std::string& path)
{
  const auto slash = path.find_last_of('/');
  std::string stem = slash == std::string::npos ? path : path.substr(slash + 1);
  const auto dot = stem.find_last_of('.');
  return dot == std::string::npos || dot == 0 ? stem : stem.substr(0, dot);
}

void closeRing(std::vector<RingText>& rings, RingText& current, const std::string& source)
{
  if (current.points.empty())
    return;
  // The closing vertex may be repeated; count distinct vertices as makePolygon will.
  std::size_t distinct = 0;
  for (std::size_t k = 0; k < current.points.size(); ++k)
    if (k == 0 || current.points[k] != current.points[k - 1])
      ++distinct;
  if (distinct > 1 && current.points.back() == current.points.front())
    --distinct;
  if (distinct < 3)
    throw InputError(source + ":" + std::to_string(current.last_line) + ": ring " + std::to_string(rings.size() + 1) +
                     " (lines " + std::to_string(current.first_line) + "-" + std::to_string(current.last_line) +
                     ") has " + std::to_string(distinct) +
                     " distinct vertices; a closed polygon needs at least 3 lines 'x y' (a blank line starts a "
                     "new ring)");
  double area2 = 0.0;
  double scale = 0.0;
  for (std::size_t i = 0, n = current.points.size(); i < n; ++i)
  {
    const Eigen::Vector2d& a = current.points[i];
    const Eigen::Vector2d& b = current.points[(i + 1) % n];
    area2 += a.x() * b.y() - a.y() * b.x();
    scale = std::max(scale, a.cwiseAbs().maxCoeff());
  }
  if (!(std::fabs(area2) > 1e-24 * std::max(scale * scale, 1e-30)))
    throw InputError(source + ":" + std::to_string(current.last_line) + ": ring " + std::to_string(rings.size() + 1) +
                     " (lines " + std::to_string(current.first_line) + "-" + std::to_string(current.last_line) +
                     ") encloses no area (all vertices on one line)");
  rings.push_back(std::move(current));
  current = RingText();
}
}  // namespace

Shape parsePolygonText(const std::string& text, const std::string& source)
{
  std::vector<RingText> rings;
  RingText current;
  std::istringstream in(text);
  std::size_t line_number = 0;
  for (std::string line; std::getline(in, line);)
  {
    ++line_number;
    const std::string where = source + ":" + std::to_string(line_number) + ": ";
    if (!line.empty() && line.back() == '\r')
      line.pop_back();  // CRLF files
    const auto hash = line.find('#');
    const bool had_comment = hash != std::string::npos;
    const std::string body = had_comment ? line.substr(0, hash) : line;
    std::istringstream fields(body);
    std::vector<std::string> tokens;
    for (std::string token; fields >> token && tokens.size() < 3;)
      tokens.push_back(token);
    if (tokens.empty())
    {
      if (!had_comment)
        closeRing(rings, current, source);  // a blank line ends the ring; comment lines do not
      continue;
    }
    if (tokens.size() != 2)
      throw InputError(where + "expected two numbers 'x y' (metres), got " + quoted(body));
    Eigen::Vector2d p;
    for (int axis = 0; axis < 2; ++axis)
    {
      double value = 0.0;
      const NumberText status = parseNumber(tokens[axis], value);
      if (status != NumberText::Ok)
        throw InputError(where + (axis == 0 ? "x" : "y") + ": " + quoted(tokens[axis]) +
                         (status == NumberText::NotFinite ? " is not a finite number" : " is not a number") +
                         " (expected 'x y' in metres)");
      p[axis] = value;
    }
    if (current.points.empty())
      current.first_line = line_number;
    current.last_line = line_number;
    current.points.push_back(p);
  }
  closeRing(rings, current, source);
  if (rings.empty())
    throw InputError(source + ":" + std::to_string(line_number) +
                     ": no vertices (expected at least 3 lines 'x y' in metres)");
  std::vector<Ring> plain;
  plain.reserve(rings.size());
  for (RingText& ring : rings)
    plain.push_back(std::move(ring.points));
  return makePolygon(std::move(plain), fileStem(source), source);
}

Shape readPolygonFile(const std::string& path)
{
  std::ifstream file(path, std::ios::binary);
  if (!file)
    throw InputError(path + ": cannot open the polygon file");
  std::ostringstream text;
  text << file.rdbuf();
  return parsePolygonText(text.str(), path);
}
}  // namespace scanhead
