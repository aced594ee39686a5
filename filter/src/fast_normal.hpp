// Fast standard normals from CounterRng raw draws (internal). The particle loops draw ~5 normals
// per particle per cycle; glibc log/sin/cos dominated the cycle at 1e6+ particles. Approximations
// here are accurate to ~1e-5 absolute, far below the process/birth noise they shape.
#pragma once

#include <cstdint>
#include <cstring>

#include "dualgrid/core/random.hpp"

namespace dualgrid::filter::detail {

/// Natural log for x in (0, 1], |error| < 2e-5. Constants are multiplied, never divided.
inline float FastLog(float x) {
  std::uint32_t bits;
  std::memcpy(&bits, &x, sizeof bits);
  const int e = static_cast<int>((bits >> 23) & 0xFF) - 127;
  bits = (bits & 0x007FFFFFu) | 0x3F800000u;  // mantissa in [1, 2)
  float m;
  std::memcpy(&m, &bits, sizeof m);
  // log(m) on [1, 2) via t = (m - 1) / (m + 1): log(m) = 2 atanh(t), |t| <= 1/3.
  const float t = (m - 1.0f) / (m + 1.0f), t2 = t * t;
  constexpr float c3 = 1.0f / 3, c5 = 1.0f / 5, c7 = 1.0f / 7, c9 = 1.0f / 9;
  const float l = 2.0f * t * (1.0f + t2 * (c3 + t2 * (c5 + t2 * (c7 + t2 * c9))));
  return static_cast<float>(e) * 0.69314718f + l;
}

/// sin and cos of 2 pi u for u in [0, 1), |error| < 1e-5; branch-free quadrant folding.
inline void FastSinCos2Pi(float u, float* s, float* c) {
  const float x = u * 4.0f;
  const int q = static_cast<int>(x);
  const float f = (x - static_cast<float>(q)) * 1.57079632679f;  // [0, pi/2)
  const float f2 = f * f;
  // Taylor series to f^9 / f^10 (remainder < 4e-6 on [0, pi/2]).
  const float sn =
      f *
      (1.0f + f2 * (-1.0f / 6 + f2 * (1.0f / 120 + f2 * (-1.0f / 5040 + f2 * (1.0f / 362880)))));
  const float cs =
      1.0f + f2 * (-0.5f + f2 * (1.0f / 24 + f2 * (-1.0f / 720 +
                                                   f2 * (1.0f / 40320 + f2 * (-1.0f / 3628800)))));
  const bool swap = (q & 1) != 0;
  const float s0 = swap ? cs : sn, c0 = swap ? sn : cs;
  *s = (q & 2) ? -s0 : s0;
  *c = ((q + 1) & 2) ? -c0 : c0;
}

/// Uniform in [0, 1) with 24 random bits (float resolution).
inline float ToUnit24(std::uint32_t r) { return static_cast<float>(r >> 8) * (1.0f / 16777216.0f); }

// The array forms (Philox blocks lane-wise, Box-Muller over arrays) are on SIMD lanes in
// simd_normals.cpp, with the same arithmetic as FastLog and FastSinCos2Pi above.

/// Two independent standard normals (Box-Muller) from two raw 32-bit draws r1, r2.
inline void Normal2FromRaw(std::uint32_t r1, std::uint32_t r2, float* a, float* b) {
  constexpr float k24 = 1.0f / 16777216.0f;
  const float u1 = (static_cast<float>(r1 >> 8) + 1.0f) * k24;  // (0, 1]
  const float u2 = static_cast<float>(r2 >> 8) * k24;           // [0, 1)
  const float r = __builtin_sqrtf(-2.0f * FastLog(u1));
  float s, c;
  FastSinCos2Pi(u2, &s, &c);
  *a = r * c;
  *b = r * s;
}

/// Two independent standard normals (Box-Muller) from two raw 32-bit draws of `rng`.
inline void Normal2(CounterRng& rng, float* a, float* b) {
  const std::uint32_t r1 = rng.NextU32();
  Normal2FromRaw(r1, rng.NextU32(), a, b);
}

/// Uniform in [0, 1) from one raw draw (24 bits: float resolution).
inline float Uniform24(CounterRng& rng) {
  return static_cast<float>(rng.NextU32() >> 8) * (1.0f / 16777216.0f);
}

}  // namespace dualgrid::filter::detail
