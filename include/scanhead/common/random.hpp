/// \file random.hpp
/// \brief The one pseudo-random generator of the core: splitmix64, with its two mappings to
/// doubles. Pure 64-bit integer arithmetic, so a seed gives the same draws on every platform and
/// compiler (std::mt19937 would too, but std::*_distribution are implementation-defined).
///
/// splitmix64 (G. L. Steele, D. Lea, C. H. Flood, "Fast splittable pseudorandom number
/// generators", OOPSLA 2014; S. Vigna's public-domain reference splitmix64.c, the seeding
/// generator of xoshiro/xoroshiro): with the Weyl increment \f$\gamma\f$ = 0x9E3779B97F4A7C15,
/// \f[ s_{k+1} = s_k + \gamma \pmod{2^{64}}, \qquad
///     z = (s_{k+1} \oplus (s_{k+1} \gg 30)) \cdot \mathrm{0xBF58476D1CE4E5B9}, \f]
/// \f[ z' = (z \oplus (z \gg 27)) \cdot \mathrm{0x94D049BB133111EB}, \qquad
///     x_{k+1} = z' \oplus (z' \gg 31), \f]
/// all products modulo \f$2^{64}\f$. Seed 0 gives 0xe220a8397b1dcdaf, 0x6e789e6aa1b965f4, ...
/// (test_random.cpp). Users: randomDefectSet (defect_catalog.hpp) and simulateMeasurements
/// (calibration.hpp); their seeded results are pinned by their tests.
#pragma once

#include <cstdint>

namespace scanhead
{
/// \brief splitmix64: 64 random bits per call from a 64-bit state (the seed).
class SplitMix64
{
public:
  /// \param[in] seed any 64-bit value (0 included)
  explicit SplitMix64(std::uint64_t seed)
    : state_(seed)
  {
  }

  /// \brief The next 64 bits.
  std::uint64_t next()
  {
    std::uint64_t z = (state_ += 0x9E3779B97F4A7C15ULL);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
    return z ^ (z >> 31);
  }

  /// \brief Uniform in [0, 1): the top 53 bits, \f$ u = (x \gg 11)\, 2^{-53} \f$ (exact).
  double uniformClosedOpen() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }

  /// \brief Uniform in (0, 1]: \f$ u = ((x \gg 11) + 1)\, 2^{-53} \f$ (exact; never 0, so
  /// \f$\ln u\f$ is finite, as Box–Muller needs).
  double uniformOpenClosed() { return (static_cast<double>(next() >> 11) + 1.0) * 0x1.0p-53; }

private:
  std::uint64_t state_;  ///< s_k
};
}  // namespace scanhead
