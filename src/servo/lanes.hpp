/// \file lanes.hpp
/// \brief Two doubles in one SSE2 register (GCC vector extension), and the few operations the
/// servo's lockstep code needs written once for double and for the 2-lane vector: a select, the
/// magnitude, a clamp and a mask conjunction. Each lane does exactly the scalar operations (IEEE
/// add, mul, div, compare; no FMA), so a lane's result is the scalar result bit for bit.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace scanhead
{
namespace lanes
{
typedef double Double2 __attribute__((vector_size(16)));
typedef std::int64_t Mask2 __attribute__((vector_size(16)));

inline double select(bool m, double a, double b)
{
  return m ? a : b;
}
inline Double2 select(Mask2 m, Double2 a, Double2 b)
{
  return m ? a : b;
}
inline bool both(bool a, bool b)
{
  return a && b;
}
inline Mask2 both(Mask2 a, Mask2 b)
{
  return a & b;
}
inline double magnitude(double v)
{
  return std::abs(v);
}
inline Double2 magnitude(Double2 v)
{
  const Mask2 sign = {INT64_MIN, INT64_MIN};
  return reinterpret_cast<Double2>(reinterpret_cast<Mask2>(v) & ~sign);
}
/// \brief std::clamp's operations: v < lo ? lo : (hi < v ? hi : v).
inline double clampTo(double v, double lo, double hi)
{
  return std::clamp(v, lo, hi);
}
inline Double2 clampTo(Double2 v, Double2 lo, Double2 hi)
{
  return v < lo ? lo : (hi < v ? hi : v);
}
/// \brief Bit i set if lane i of the mask is set (one movmskpd).
inline int laneBits(Mask2 m)
{
  return __builtin_ia32_movmskpd(reinterpret_cast<Double2>(m));
}
}  // namespace lanes
}  // namespace scanhead
