// Prediction of a particle range (internal): lets DynamicGrid fuse the prediction with the first
// pass of the counting sort (one read of the particles instead of two).
#pragma once

#include <cstdint>

#include "dualgrid/filter/particles.hpp"

namespace dualgrid::filter::detail {

/// Particles per Philox / Box-Muller batch.
inline constexpr std::int64_t kPredictBlock = 256;

/// PredictParticles (particles.hpp) for particles [lo, hi) only, serial, with the noise scales
/// already in float: sp = float(sigma_pos sqrt(dt)), sv = float(sigma_vel sqrt(dt)).
void PredictRange(ParticleSet& p, std::int64_t lo, std::int64_t hi, double dt, float sp, float sv,
                  double persistence, std::uint64_t seed, std::uint64_t step);

}  // namespace dualgrid::filter::detail
