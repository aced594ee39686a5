// Test reference (tests/filter/test_float_bound.cpp): the double filter cycle of commit 27d8ca3
// (before issue 37), namespace dualgrid::filter_ref. Not part of the library.
#include "particles.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>

#include <omp.h>

#include "dualgrid/core/parallel.hpp"
#include "dualgrid/core/random.hpp"
#include "fast_normal.hpp"
#include "predict.hpp"
#include "prediction_noise.hpp"

namespace dualgrid::filter {}  // namespace dualgrid::filter

namespace dualgrid::filter_ref {
using namespace ::dualgrid::filter;  // FilterParams, Measurement, SensorCoverage

void ParticleSet::resize(std::size_t n) {
  x.resize(n);
  y.resize(n);
  for (auto* v : {&vx, &vy, &w_position, &w_velocity, &weight}) v->resize(n);
}

namespace detail {

void PredictionNormals(std::uint64_t seed, std::uint64_t step, std::int64_t b0, std::int64_t m,
                       float* g0, float* g1, float* g2, float* g3) {
  assert(m <= kPredictBlock);
  alignas(64) std::uint32_t raw[4][kPredictBlock];
  alignas(64) float u[4][kPredictBlock];
  PhiloxBlocks(seed, RngPurpose::kFilterPredict, step, static_cast<std::uint32_t>(b0), m, 0, raw[0],
               raw[1], raw[2], raw[3]);
  for (int c = 0; c < 4; ++c) {
    for (std::int64_t k = 0; k < m; ++k) u[c][k] = ToUnit24(raw[c][k]);
  }
  BoxMuller(u[0], u[1], g0, g1, m);
  BoxMuller(u[2], u[3], g2, g3, m);
}

void PredictRange(ParticleSet& p, std::int64_t lo, std::int64_t hi, double dt, float sp, float sv,
                  double persistence, std::uint64_t seed, std::uint64_t step,
                  const PredictionNoise* shared) {
  const bool noisy = sp > 0.0f || sv > 0.0f;
  // Blocks of particles: raw Philox draws first, then the Box-Muller transform as straight-line
  // array code the compiler vectorises (the scalar transform cost ~4x more per particle). Every
  // particle's noise depends on its index only, so any blocking gives the same result, and so
  // do the shared draws (PredictionNoise: the same function over other blocks).
  constexpr std::int64_t kBlock = kPredictBlock;
  for (std::int64_t b0 = lo; b0 < hi; b0 += kBlock) {
    const std::int64_t m = std::min(kBlock, hi - b0);
    alignas(64) float own[4][kBlock];
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
    for (std::int64_t k = 0; k < m; ++k) {
      const std::int64_t i = b0 + k;
      p.x[i] += p.vx[i] * dt + sp * g[0][k];
      p.y[i] += p.vy[i] * dt + sp * g[1][k];
      p.vx[i] += sv * g[2][k];
      p.vy[i] += sv * g[3][k];
      p.weight[i] *= persistence;
      p.w_position[i] *= persistence;
      p.w_velocity[i] *= persistence;
    }
  }
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
    detail::PredictRange(p, b * kBlock, std::min(n, (b + 1) * kBlock), dt, sp, sv, persistence,
                         seed, step, nullptr);
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

}  // namespace dualgrid::filter_ref
