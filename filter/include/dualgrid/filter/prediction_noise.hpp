// The standard normal draws of one cycle's prediction (step 2, paper eq. 5's process noise),
// drawn once and shared by filters that would draw the same ones. docs/algorithm.md, step 2.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

namespace dualgrid::filter {

/// Per particle index i the four standard normals (x, y, vx, vy) that DynamicGrid's prediction
/// draws in cycle `step` of a filter with seed `seed`: counter-based (Philox keyed by seed, step
/// and i), so they depend on nothing else. Filters with the same seed and step count (the
/// co-simulation's weight modes, updated in lockstep) draw the same values; the co-simulation
/// draws them once per step and passes them to every mode's DynamicGrid::Update: same results,
/// bit for bit, as each drawing its own.
///
/// Memory: 16 bytes per particle, allocated by the first Draw and reused.
class PredictionNoise {
 public:
  /// Draws the normals of particles [0, n) for (seed, step). n >= 0. O(n); parallel over
  /// blocks (OpenMP) when called outside a parallel region.
  void Draw(std::uint64_t seed, std::uint64_t step, std::int64_t n);

  /// True if the last Draw was for exactly this seed and step and at least n particles.
  bool Holds(std::uint64_t seed, std::uint64_t step, std::int64_t n) const {
    return drawn_ && seed_ == seed && step_ == step && n_ >= n;
  }
  /// Channel c (0: x, 1: y, 2: vx, 3: vy) of particle i; requires i < the drawn count.
  const float* channel(int c) const { return g_[c].data(); }

 private:
  std::array<std::vector<float>, 4> g_;
  std::uint64_t seed_ = 0, step_ = 0;
  std::int64_t n_ = 0;
  bool drawn_ = false;
};

}  // namespace dualgrid::filter
