/// \file lane_math.hpp
/// \brief exp and erf on 8 float lanes (GCC vector extensions), for the row kernels of stroke_deposit.cpp (private
/// to src/energy).
///
/// Only add, multiply, divide, compare and integer bit operations, and no FMA contraction (the AVX2 target does not
/// enable FMA, and the energy library builds with -ffp-contract=off): every clone of a caller (target_clones
/// "avx2" / "default") computes the same bits, so maps do not depend on the machine's vector width.
#pragma once

#include <cstdint>

// Every helper is inlined into its (cloned) caller, so 32-byte vectors never cross a call: GCC's note on their ABI
// without AVX does not apply.
#pragma GCC diagnostic ignored "-Wpsabi"
#define SCANHEAD_LANE_INLINE inline __attribute__((always_inline))

namespace scanhead::energy_detail
{
typedef float F8 __attribute__((vector_size(32)));
typedef std::int32_t I8 __attribute__((vector_size(32)));

SCANHEAD_LANE_INLINE F8 splat(float x)
{
  return F8{x, x, x, x, x, x, x, x};
}

/// \brief {0, 1, …, 7}: the lane offsets of a block of 8 consecutive pixels.
SCANHEAD_LANE_INLINE F8 laneIndex()
{
  return F8{0.0f, 1.0f, 2.0f, 3.0f, 4.0f, 5.0f, 6.0f, 7.0f};
}

/// \brief {0, 1, …, 7} as integers.
SCANHEAD_LANE_INLINE I8 laneIndexInt()
{
  return I8{0, 1, 2, 3, 4, 5, 6, 7};
}

/// \brief Adds the lanes of \p value below \p count (a row's last, partial block) to \p sum.
SCANHEAD_LANE_INLINE void accumulate(F8& sum, F8 value, int count)
{
  sum += count >= 8 ? value : (laneIndex() < splat(static_cast<float>(count)) ? value : splat(0.0f));
}

/// \brief Σ of the 8 lanes in a fixed order, in double.
SCANHEAD_LANE_INLINE double laneSum(F8 sum)
{
  double total = 0.0;
  for (int l = 0; l < 8; ++l)
    total += static_cast<double>(sum[l]);
  return total;
}

/// \brief e^{−x}, x clamped to [−88, 87] (x > 87 gives e^{−87} ≈ 1.6e-38 instead of less: harmless against weights
/// ≥ 1e-6; x < −88 gives e^{88} ≈ 1.7e38 instead of more, never garbage: 2ⁿ stays a normal float).
///
/// Cephes expf (S. L. Moshier, Cephes Math Library, expf.c): e^y = 2ⁿ·e^r with n = round(y/ln 2) (by the 1.5·2²³
/// rounding trick, round to nearest), r = y − n·ln 2 in two parts (Cody–Waite: 0.693359375 is exact in float, so
/// n·C1 is exact), e^r = 1 + r + r²·P(r) with the minimax degree-5 P of Cephes on |r| ≤ ln2/2: relative error
/// ≤ 2 ulp in float arithmetic (measured against std::exp in test_stroke_deposit.cpp).
SCANHEAD_LANE_INLINE F8 expNeg(F8 x)
{
  const F8 low = x < splat(87.0f) ? x : splat(87.0f);
  const F8 y = -(low > splat(-88.0f) ? low : splat(-88.0f));
  const F8 round_bias = splat(12582912.0f);  // 1.5·2²³
  const F8 n = (y * splat(1.44269504088896341f) + round_bias) - round_bias;
  F8 r = y - n * splat(0.693359375f);
  r = r - n * splat(-2.12194440e-4f);
  F8 p = splat(1.9875691500e-4f);
  p = p * r + splat(1.3981999507e-3f);
  p = p * r + splat(8.3334519073e-3f);
  p = p * r + splat(4.1665795894e-2f);
  p = p * r + splat(1.6666665459e-1f);
  p = p * r + splat(5.0000001201e-1f);
  const F8 e = (p * (r * r) + r) + splat(1.0f);
  const I8 scale = (__builtin_convertvector(n, I8) + 127) << 23;  // 2ⁿ, n ∈ [−126, 127]
  return e * reinterpret_cast<F8>(scale);
}

/// \brief erf x by Abramowitz & Stegun 7.1.28: erf|x| = 1 − 1/(1 + a₁x + a₂x² + … + a₆x⁶)¹⁶, |error| ≤ 3e-7; odd.
///
/// No exponential (a polynomial, four squarings and a division: ~18 lane operations instead of ~35 for 7.1.26 with
/// its e^{−x²}). In float the 16th power amplifies the polynomial's rounding (≤ 2 ulp) 16 times: ≤ 4e-6·erfc|x|
/// absolute, so |error| ≤ 4e-6 everywhere and → 0 where erf → ±1 (checked against std::erf by the tests).
SCANHEAD_LANE_INLINE F8 erfLanes(F8 x)
{
  const I8 sign_bit = I8{} + static_cast<std::int32_t>(0x80000000u);
  const I8 bits = reinterpret_cast<I8>(x);
  const F8 a = reinterpret_cast<F8>(bits & ~sign_bit);
  F8 poly = splat(0.0000430638f);
  poly = poly * a + splat(0.0002765672f);
  poly = poly * a + splat(0.0001520143f);
  poly = poly * a + splat(0.0092705272f);
  poly = poly * a + splat(0.0422820123f);
  poly = poly * a + splat(0.0705230784f);
  poly = poly * a + splat(1.0f);
  poly = poly * poly;  // ²
  poly = poly * poly;  // ⁴
  poly = poly * poly;  // ⁸
  poly = poly * poly;  // ¹⁶ (overflows to +inf beyond |x| ≈ 60: 1/inf = 0, erf = 1)
  const F8 value = splat(1.0f) - splat(1.0f) / poly;
  return reinterpret_cast<F8>(reinterpret_cast<I8>(value) | (bits & sign_bit));
}
}  // namespace scanhead::energy_detail
