// Philox normals on SIMD lanes (Highway, the filter's pinned static target): the prediction's
// process noise (paper eq. 5) drawn four particles at a time. Public so that bench/'s floor kernel
// (bench/floor_cycle.cpp) draws the same values with the same code.
#pragma once

#include <cstdint>

namespace dualgrid::filter::detail {

/// Philox4x32-10 block `block` of the streams CounterRng(seed, purpose, step, first + k) for k in
/// [0, n), lane-wise into out0..3[k] (as Random123's philox4x32: bit for bit the scalar
/// PhiloxBlocks of fast_normal.hpp). `purpose` is RngPurpose's value. n >= 0.
void PhiloxLanes(std::uint64_t seed, std::uint32_t purpose, std::uint64_t step, std::uint32_t first,
                 std::int64_t n, std::uint32_t block, std::uint32_t* out0, std::uint32_t* out1,
                 std::uint32_t* out2, std::uint32_t* out3);

/// The four standard normals (x, y, vx, vy) of particles [first, first + n) of cycle `step`
/// (RngPurpose::kFilterPredict, block 0; Box-Muller of the 24-bit uniforms with fast_normal.hpp's
/// FastLog and FastSinCos2Pi, |error| < 2e-5): bit for bit the values of the scalar path
/// (PhiloxBlocks, BoxMuller).
void PredictionNormalLanes(std::uint64_t seed, std::uint64_t step, std::uint32_t first,
                           std::int64_t n, float* g0, float* g1, float* g2, float* g3);

/// ToUnit24 (fast_normal.hpp) of r[k] for k in [0, n): out[k] = (r[k] >> 8) / 2^24, in [0, 1).
void Unit24Lanes(const std::uint32_t* r, std::int64_t n, float* out);

/// Normal2FromRaw (fast_normal.hpp) of (r1[k], r2[k]) for k in [0, n) into (a[k], b[k]): the
/// Box-Muller pair of log argument ((r1 >> 8) + 1) / 2^24 in (0, 1], bit for bit the scalar values.
void Normal2Lanes(const std::uint32_t* r1, const std::uint32_t* r2, std::int64_t n, float* a,
                  float* b);

}  // namespace dualgrid::filter::detail
