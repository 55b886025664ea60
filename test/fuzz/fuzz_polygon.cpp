/// \file fuzz_polygon.cpp
/// \brief libFuzzer target over the polygon file reader (parsePolygonText): any input must either
/// give a shape of simple, mutually disjoint rings (≥ 3 finite vertices, non-zero area; checked
/// here by brute force over all edge pairs) or throw InputError. Build: see fuzz_smoke.sh.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>

#include "scanhead/common/errors.hpp"
#include "scanhead/job/generators/shape.hpp"

namespace
{
double turn(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c)
{
  return (b.x() - a.x()) * (c.y() - a.y()) - (b.y() - a.y()) * (c.x() - a.x());
}

/// Proper crossing of ab and cd (the reader also rejects touching; a proper crossing is the
/// independent part of the oracle).
bool properlyCross(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c,
                   const Eigen::Vector2d& d)
{
  const double d1 = turn(a, b, c), d2 = turn(a, b, d), d3 = turn(c, d, a), d4 = turn(c, d, b);
  return ((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0));
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
  const std::string text(reinterpret_cast<const char*>(data), size);
  scanhead::Shape shape;
  try
  {
    shape = scanhead::parsePolygonText(text, "fuzz.txt");
  }
  catch (const scanhead::InputError&)
  {
    return 0;
  }
  if (shape.rings.empty())
    __builtin_trap();
  struct E
  {
    std::size_t r, k, n;
    Eigen::Vector2d a, b;
  };
  std::vector<E> edges;
  for (std::size_t r = 0; r < shape.rings.size(); ++r)
  {
    const scanhead::Ring& ring = shape.rings[r];
    if (ring.size() < 3)
      __builtin_trap();
    for (std::size_t k = 0; k < ring.size(); ++k)
    {
      if (!ring[k].allFinite())
        __builtin_trap();
      edges.push_back({r, k, ring.size(), ring[k], ring[(k + 1) % ring.size()]});
    }
  }
  for (std::size_t i = 0; i < edges.size(); ++i)
    for (std::size_t j = i + 1; j < edges.size(); ++j)
    {
      const E& u = edges[i];
      const E& v = edges[j];
      if (u.r == v.r && (v.k == (u.k + 1) % u.n || u.k == (v.k + 1) % u.n))
        continue;
      if (properlyCross(u.a, u.b, v.a, v.b))
        __builtin_trap();
    }
  return 0;
}
