// Prediction of a particle range (internal): lets DynamicGrid fuse the prediction with the first
// pass of the counting sort (one read of the particles instead of two).
#pragma once

#include <algorithm>
#include <cstdint>

#include "dualgrid/filter/particles.hpp"
#include "dualgrid/filter/prediction_noise.hpp"

namespace dualgrid::filter::detail {

/// Particles per Philox / Box-Muller batch.
inline constexpr std::int64_t kPredictBlock = 256;

/// The four standard normals (x, y, vx, vy) of particles [b0, b0 + m), m <= kPredictBlock, for
/// (seed, step): Philox draws, then Box-Muller. Each particle's values depend on its index only.
void PredictionNormals(std::uint64_t seed, std::uint64_t step, std::int64_t b0, std::int64_t m,
                       float* g0, float* g1, float* g2, float* g3);

/// Where and how positions move in PredictRange: x <- (x - shift_x) + (vx dt + sp g) scale,
/// in the set's position type Pos (double for ParticleSet, float for the grid's cell-unit
/// LocalParticles: scale 1 / resolution, shift the whole cells the grid moved this cycle).
template <typename Pos>
struct PositionMap {
  Pos dt, scale = Pos(1), shift_x = Pos(0), shift_y = Pos(0);
};

/// PredictParticles (particles.hpp) for particles [lo, hi) only, serial, with the noise scales
/// already in float: sp = float(sigma_pos sqrt(dt)), sv = float(sigma_vel sqrt(dt)). `shared`,
/// if not null, holds (seed, step)'s normals for at least [0, hi) (PredictionNoise::Holds) and is
/// read instead of drawing them: the same values. Set: ParticleSet or detail::LocalParticles.
template <typename Set, typename Pos>
void PredictRange(Set& p, std::int64_t lo, std::int64_t hi, const PositionMap<Pos>& map, float sp,
                  float sv, double persistence, std::uint64_t seed, std::uint64_t step,
                  const PredictionNoise* shared) {
  const bool noisy = sp > 0.0f || sv > 0.0f;
  // Blocks of particles: raw Philox draws first, then the Box-Muller transform as straight-line
  // array code the compiler vectorises. Every particle's noise depends on its index only, so any
  // blocking gives the same result, and so do the shared draws (PredictionNoise).
  for (std::int64_t b0 = lo; b0 < hi; b0 += kPredictBlock) {
    const std::int64_t m = std::min(kPredictBlock, hi - b0);
    alignas(64) float own[4][kPredictBlock];
    const float* g[4];
    if (noisy && shared != nullptr) {
      for (int c = 0; c < 4; ++c) g[c] = shared->channel(c) + b0;
    } else {
      if (noisy) {
        PredictionNormals(seed, step, b0, m, own[0], own[1], own[2], own[3]);
      } else {
        for (int c = 0; c < 4; ++c) std::fill_n(own[c], m, 0.0f);
      }
      for (int c = 0; c < 4; ++c) g[c] = own[c];
    }
    auto* const x = p.x.data() + b0;
    auto* const y = p.y.data() + b0;
    float* const vx = p.vx.data() + b0;
    float* const vy = p.vy.data() + b0;
    float* const w = p.weight.data() + b0;
    float* const wp = p.w_position.data() + b0;
    float* const wv = p.w_velocity.data() + b0;
    for (std::int64_t k = 0; k < m; ++k) {
      x[k] = (x[k] - map.shift_x) + (vx[k] * map.dt + sp * g[0][k]) * map.scale;
      y[k] = (y[k] - map.shift_y) + (vy[k] * map.dt + sp * g[1][k]) * map.scale;
      vx[k] += sv * g[2][k];
      vy[k] += sv * g[3][k];
      w[k] *= persistence;
      wp[k] *= persistence;
      wv[k] *= persistence;
    }
  }
}

}  // namespace dualgrid::filter::detail
