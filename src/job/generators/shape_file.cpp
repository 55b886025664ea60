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
  std::vector<std::size_t> lines;  ///< the line of each vertex
  std::size_t first_line = 0;
  std::size_t last_line = 0;
};

/// Most vertices a polygon file may have: the crossing check below is O(n log n) on outlines whose
/// edges are short against the part, O(n²) at worst (measured: a comb of 5000 teeth, 20 000 vertices
/// whose 10 000 long edges all overlap along the sweep axis, 0.22 s).
constexpr std::size_t kMaxPolygonVertices = 20000;

/// One edge of a ring, from vertex k to vertex k + 1 (mod n), with its bounding box.
struct Edge
{
  std::size_t ring = 0, k = 0, n = 0;
  Eigen::Vector2d a, b;
  double lo = 0.0, hi = 0.0;  ///< extent along the sweep axis
};

/// Sign of the turn a → b → c (exact for the cases that matter: collinear points give 0 only
/// when the products round to equal values).
double turn(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c)
{
  return (b.x() - a.x()) * (c.y() - a.y()) - (b.y() - a.y()) * (c.x() - a.x());
}

/// Whether collinear point p lies within the bounding box of segment ab.
bool within(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& p)
{
  return std::min(a.x(), b.x()) <= p.x() && p.x() <= std::max(a.x(), b.x()) && std::min(a.y(), b.y()) <= p.y() &&
         p.y() <= std::max(a.y(), b.y());
}

/// Whether closed segments ab and cd share a point.
bool segmentsMeet(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c,
                  const Eigen::Vector2d& d)
{
  const double d1 = turn(a, b, c), d2 = turn(a, b, d), d3 = turn(c, d, a), d4 = turn(c, d, b);
  if (((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0)))
    return true;
  return (d1 == 0 && within(a, b, c)) || (d2 == 0 && within(a, b, d)) || (d3 == 0 && within(c, d, a)) ||
         (d4 == 0 && within(c, d, b));
}

/// Rejects outlines whose edges cross or touch (other than consecutive edges at their shared
/// vertex), within a ring or between rings: the even-odd fill and the inward offsets of the
/// generators assume simple, disjoint rings. Sort-and-sweep along the longer axis of the shape.
void checkSimple(const std::vector<RingText>& rings, const std::string& source)
{
  std::vector<Edge> edges;
  Eigen::Vector2d lo(HUGE_VAL, HUGE_VAL), hi(-HUGE_VAL, -HUGE_VAL);
  for (std::size_t r = 0; r < rings.size(); ++r)
  {
    const Ring& p = rings[r].points;
    for (std::size_t k = 0; k < p.size(); ++k)
    {
      edges.push_back({r, k, p.size(), p[k], p[(k + 1) % p.size()], 0.0, 0.0});
      lo = lo.cwiseMin(p[k]);
      hi = hi.cwiseMax(p[k]);
    }
  }
  const int axis = hi.x() - lo.x() >= hi.y() - lo.y() ? 0 : 1;
  for (Edge& e : edges)
  {
    e.lo = std::min(e.a[axis], e.b[axis]);
    e.hi = std::max(e.a[axis], e.b[axis]);
  }
  std::sort(edges.begin(), edges.end(), [](const Edge& u, const Edge& v) {
    return u.lo != v.lo       ? u.lo < v.lo
           : u.ring != v.ring ? u.ring < v.ring
                              : u.k < v.k;  // total: same message on every platform
  });
  auto name = [&](const Edge& e) {
    const RingText& ring = rings[e.ring];
    return "ring " + std::to_string(e.ring + 1) + " edge lines " + std::to_string(ring.lines[e.k]) + "-" +
           std::to_string(ring.lines[(e.k + 1) % e.n]);
  };
  for (std::size_t i = 0; i < edges.size(); ++i)
  {
    const Edge& u = edges[i];
    for (std::size_t j = i + 1; j < edges.size() && edges[j].lo <= u.hi; ++j)
    {
      const Edge& v = edges[j];
      const int other = 1 - axis;
      if (std::max(u.a[other], u.b[other]) < std::min(v.a[other], v.b[other]) ||
          std::max(v.a[other], v.b[other]) < std::min(u.a[other], u.b[other]))
        continue;
      bool meet = false;
      if (u.ring == v.ring && (v.k == (u.k + 1) % u.n || u.k == (v.k + 1) % u.n))
      {
        // Consecutive edges share a vertex; they only fail by folding back onto each other.
        const bool u_first = v.k == (u.k + 1) % u.n;
        const Edge& first = u_first ? u : v;
        const Edge& second = u_first ? v : u;
        meet = turn(first.a, first.b, second.b) == 0 && (first.b - first.a).dot(second.b - second.a) < 0;
      }
      else
        meet = segmentsMeet(u.a, u.b, v.a, v.b);
      if (meet)
      {
        const Edge& first = u.ring < v.ring || (u.ring == v.ring && u.k < v.k) ? u : v;
        const Edge& second = &first == &u ? v : u;
        throw InputError(source + ":" + std::to_string(rings[second.ring].lines[second.k]) +
                         ": the outline crosses itself: " + name(first) + " and " + name(second) +
                         " cross or touch (rings must be simple and disjoint)");
      }
    }
  }
}

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
  // Drop consecutive duplicates and the repeated closing vertex, as makePolygon does, keeping the
  // line of each vertex for the crossing check's messages.
  {
    RingText distinct_ring;
    distinct_ring.first_line = current.first_line;
    distinct_ring.last_line = current.last_line;
    for (std::size_t k = 0; k < current.points.size(); ++k)
    {
      if (k > 0 && current.points[k] == current.points[k - 1])
        continue;
      distinct_ring.points.push_back(current.points[k]);
      distinct_ring.lines.push_back(current.lines[k]);
    }
    while (distinct_ring.points.size() > 1 && distinct_ring.points.back() == distinct_ring.points.front())
    {
      distinct_ring.points.pop_back();
      distinct_ring.lines.pop_back();
    }
    current = std::move(distinct_ring);
  }
  const std::size_t distinct = current.points.size();
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
  std::size_t vertices = 0;
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
    current.lines.push_back(line_number);
    if (++vertices > kMaxPolygonVertices)
      throw InputError(where + "more than " + std::to_string(kMaxPolygonVertices) +
                       " vertices: a polygon file holds a part's outline; simplify it (e.g. 1 µm chord tolerance)");
  }
  closeRing(rings, current, source);
  if (rings.empty())
    throw InputError(source + ":" + std::to_string(line_number) +
                     ": no vertices (expected at least 3 lines 'x y' in metres)");
  checkSimple(rings, source);
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
  // kMaxPolygonVertices lines of "x y" fit in ~1 MB; comments included, 16 MiB is plenty.
  constexpr std::streamoff kMaxBytes = 16 << 20;
  file.seekg(0, std::ios::end);
  const std::streamoff size = file.tellg();
  file.seekg(0, std::ios::beg);
  if (size > kMaxBytes)
    throw InputError(path + ": " + std::to_string(size) + " bytes is more than the 16 MiB a polygon file may have (" +
                     std::to_string(kMaxPolygonVertices) + " vertices at most)");
  std::ostringstream text;
  text << file.rdbuf();
  return parsePolygonText(text.str(), path);
}
}  // namespace scanhead
