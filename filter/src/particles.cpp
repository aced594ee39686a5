#include "dualgrid/filter/particles.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>

#include <omp.h>

#include "dualgrid/core/parallel.hpp"
#include "dualgrid/core/random.hpp"
#include "dualgrid/filter/prediction_noise.hpp"
#include "dualgrid/filter/simd_normals.hpp"
#include "predict.hpp"

namespace dualgrid::filter {

void ParticleSet::resize(std::size_t n) {
  x.resize(n);
  y.resize(n);
  for (auto* v : {&vx, &vy, &w_position, &w_velocity, &weight}) v->resize(n);
}

namespace detail {

void PredictionNormals(std::uint64_t seed, std::uint64_t step, std::int64_t b0, std::int64_t m,
                       float* g0, float* g1, float* g2, float* g3) {
  assert(m <= kPredictBlock);
  PredictionNormalLanes(seed, step, static_cast<std::uint32_t>(b0), m, g0, g1, g2, g3);
}

}  // namespace detail

void PredictParticles(ParticleSet& p, double dt, double sigma_pos, double sigma_vel,
                      double persistence, std::uint64_t seed, std::uint64_t step) {
  const float sp = static_cast<float>(sigma_pos * std::sqrt(dt));
  const float sv = static_cast<float>(sigma_vel * std::sqrt(dt));
  const std::int64_t n = static_cast<std::int64_t>(p.size());
  constexpr std::int64_t kBlock = detail::kPredictBlock;
  const std::int64_t blocks = (n + kBlock - 1) / kBlock;
  ParallelFor(blocks, Schedule::kStatic, [&](std::int64_t b) {
    detail::PredictRange(p, b * kBlock, std::min(n, (b + 1) * kBlock),
                         detail::PositionMap<double>{dt}, sp, sv, persistence, seed, step, nullptr);
  });
}

void PredictionNoise::Draw(std::uint64_t seed, std::uint64_t step, std::int64_t n) {
  assert(n >= 0);
  drawn_ = false;  // a failed allocation leaves no stale match
  for (auto& c : g_) c.resize(static_cast<std::size_t>(n));
  constexpr std::int64_t kBlock = detail::kPredictBlock;
  const std::int64_t blocks = (n + kBlock - 1) / kBlock;
  // Inside a parallel region (the co-simulation draws the next step's noise on one mode thread
  // while the others filter) on that thread alone, whatever nesting would allow.
  ParallelFor(
      blocks, Schedule::kStatic,
      [&](std::int64_t b) {
        const std::int64_t b0 = b * kBlock, m = std::min(kBlock, n - b0);
        detail::PredictionNormals(seed, step, b0, m, g_[0].data() + b0, g_[1].data() + b0,
                                  g_[2].data() + b0, g_[3].data() + b0);
      },
      /*worth=*/!omp_in_parallel());
  seed_ = seed;
  step_ = step;
  n_ = n;
  drawn_ = true;
}

namespace {

// Fixed block size: the summation tree depends on the input size only.
constexpr std::int64_t kScanBlock = 1 << 14;

template <typename T>
void ExclusiveScanImpl(std::span<const T> in, std::span<T> out) {
  assert(out.size() == in.size() + 1);
  const std::int64_t n = static_cast<std::int64_t>(in.size());
  const std::int64_t blocks = (n + kScanBlock - 1) / kScanBlock;
  if (blocks <= 1) {
    T acc = T(0);
    for (std::int64_t i = 0; i < n; ++i) {
      out[i] = acc;
      acc += in[i];
    }
    out[n] = acc;
    return;
  }
  // Block totals live apart from `out` (adjacent blocks would otherwise share a slot). The small
  // vector grows once per thread and is then reused, keeping the cycle allocation-free.
  static thread_local std::vector<T> base;
  if (base.size() < static_cast<std::size_t>(blocks) + 1) base.resize(blocks + 1);
  T* const tot = base.data();  // the caller's copy, shared with the team below
  // Pass 1: block totals.
  ParallelFor(blocks, Schedule::kStatic, [&](std::int64_t b) {
    const std::int64_t lo = b * kScanBlock, hi = std::min(n, lo + kScanBlock);
    T acc = T(0);
    for (std::int64_t i = lo; i < hi; ++i) acc += in[i];
    tot[b + 1] = acc;
  });
  // Serial scan over block totals (few entries).
  tot[0] = T(0);
  for (std::int64_t b = 0; b < blocks; ++b) tot[b + 1] += tot[b];
  // Pass 2: local scans from each block's base.
  ParallelFor(blocks, Schedule::kStatic, [&](std::int64_t b) {
    const std::int64_t lo = b * kScanBlock, hi = std::min(n, lo + kScanBlock);
    T acc = tot[b];
    for (std::int64_t i = lo; i < hi; ++i) {
      out[i] = acc;
      acc += in[i];
    }
  });
  out[n] = tot[blocks];
}

}  // namespace

void ExclusiveScan(std::span<const double> in, std::span<double> out) {
  ExclusiveScanImpl<double>(in, out);
}
void ExclusiveScan(std::span<const std::int64_t> in, std::span<std::int64_t> out) {
  ExclusiveScanImpl<std::int64_t>(in, out);
}

void SystematicRanges(std::span<const double> cumulative, std::size_t n_out, double u,
                      std::span<std::int64_t> start) {
  assert(start.size() == cumulative.size());
  const std::int64_t n_src = static_cast<std::int64_t>(cumulative.size()) - 1;
  const double total = cumulative[n_src];
  assert(total > 0.0);
  const double scale = static_cast<double>(n_out) / total;
  const std::int64_t n = static_cast<std::int64_t>(n_out);
  // Slot k is drawn from the source whose interval holds (k + u) * total / n_out, i.e. source i
  // owns slots k with cumulative[i] * scale - u <= k < cumulative[i + 1] * scale - u.
  ParallelFor(n_src + 1, Schedule::kStatic, [&](std::int64_t i) {
    const double k = std::ceil(cumulative[i] * scale - u);
    start[i] = std::clamp(static_cast<std::int64_t>(k), std::int64_t{0}, n);
  });
  start[0] = 0;
  start[n_src] = n;
}

}  // namespace dualgrid::filter
