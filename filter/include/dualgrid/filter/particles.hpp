// Particle storage (structure of arrays) and the thread-count-independent building blocks of the
// particle filter: prediction, deterministic prefix sums and systematic resampling ranges.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace dualgrid::filter {

/// dst's particle k = src's particle i, all seven fields (ParticleSet or the filter's
/// detail::LocalParticles: the same field names).
template <typename Set>
void CopyParticle(const Set& src, std::size_t i, Set& dst, std::size_t k) {
  dst.x[k] = src.x[i];
  dst.y[k] = src.y[i];
  dst.vx[k] = src.vx[i];
  dst.vy[k] = src.vy[i];
  dst.w_position[k] = src.w_position[i];
  dst.w_velocity[k] = src.w_velocity[i];
  dst.weight[k] = src.weight[i];
}

/// Particles in the filter's frame (the caller's; in dualgrid the grid frame, docs/algorithm.md)
/// [m], [m/s]. Positions are double (coordinates can be far from the origin: the grid frame only
/// turns the world's, keeping their magnitude); velocities and weights are float, which halves the
/// memory traffic of the particle loops at 1e6+ particles. All weights are dynamic-mass units (see
/// docs/algorithm.md): `weight` is the resample weight (w_resample, eq. 14, or the single weight of
/// the selected mode); w_position / w_velocity are the per-cell normalised weights of eqs. (7)/(8),
/// carried through resampling with their ratio to `weight` preserved.
struct ParticleSet {
  std::vector<double> x, y;
  std::vector<float> vx, vy;
  std::vector<float> w_position, w_velocity, weight;

  std::size_t size() const { return x.size(); }
  void resize(std::size_t n);
  /// Copies particle `src_index` of `src` into slot `dst_index` of this set.
  void CopyFrom(const ParticleSet& src, std::size_t src_index, std::size_t dst_index) {
    CopyParticle(src, src_index, *this, dst_index);
  }
};

/// Constant-velocity prediction over `dt` [s]: position += v dt + N(0, sigma_pos^2 dt), velocity +=
/// N(0, sigma_vel^2 dt); all three weights times `persistence`. Noise of particle i comes from
/// CounterRng(seed, kFilterPredict, step, i). With zero sigmas the motion is exact.
void PredictParticles(ParticleSet& particles, double dt, double sigma_pos, double sigma_vel,
                      double persistence, std::uint64_t seed, std::uint64_t step);

/// out[i] = sum of in[0..i) (out has in.size() + 1 entries; out.back() is the total). Summation
/// order depends only on the size, never on the thread count, so double results are reproducible.
void ExclusiveScan(std::span<const double> in, std::span<double> out);
void ExclusiveScan(std::span<const std::int64_t> in, std::span<std::int64_t> out);

/// Systematic (low-variance) resampling as output ranges: given the exclusive prefix sums
/// `cumulative` of the source weights (size n_src + 1, total = cumulative.back() > 0), `n_out`
/// draws at offsets (k + u) * total / n_out, u in [0, 1), source i receives output slots
/// [start[i], start[i + 1]). `start` has n_src + 1 entries, start[0] = 0, start[n_src] = n_out.
void SystematicRanges(std::span<const double> cumulative, std::size_t n_out, double u,
                      std::span<std::int64_t> start);

}  // namespace dualgrid::filter
