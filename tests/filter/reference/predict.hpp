// Test reference (tests/filter/test_float_bound.cpp): the double filter cycle of commit 27d8ca3
// (before issue 37), namespace dualgrid::filter_ref. Not part of the library.
// Prediction of a particle range (internal): lets DynamicGrid fuse the prediction with the first
// pass of the counting sort (one read of the particles instead of two).
#pragma once

#include <cstdint>

#include "particles.hpp"
#include "prediction_noise.hpp"

namespace dualgrid::filter {}  // namespace dualgrid::filter

namespace dualgrid::filter_ref::detail {
using namespace ::dualgrid::filter;

/// Particles per Philox / Box-Muller batch.
inline constexpr std::int64_t kPredictBlock = 256;

/// The four standard normals (x, y, vx, vy) of particles [b0, b0 + m), m <= kPredictBlock, for
/// (seed, step): Philox draws, then Box-Muller. Each particle's values depend on its index only.
void PredictionNormals(std::uint64_t seed, std::uint64_t step, std::int64_t b0, std::int64_t m,
                       float* g0, float* g1, float* g2, float* g3);

/// PredictParticles (particles.hpp) for particles [lo, hi) only, serial, with the noise scales
/// already in float: sp = float(sigma_pos sqrt(dt)), sv = float(sigma_vel sqrt(dt)). `shared`,
/// if not null, holds (seed, step)'s normals for at least [0, hi) (PredictionNoise::Holds) and is
/// read instead of drawing them: the same values.
void PredictRange(ParticleSet& p, std::int64_t lo, std::int64_t hi, double dt, float sp, float sv,
                  double persistence, std::uint64_t seed, std::uint64_t step,
                  const PredictionNoise* shared);

}  // namespace dualgrid::filter_ref::detail
