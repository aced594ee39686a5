// Test reference (tests/filter/test_float_bound.cpp): the double filter cycle of commit 27d8ca3
// (before issue 37), namespace dualgrid::filter_ref. Not part of the library.
// Steps 2-3 of the cycle (docs/algorithm.md): prediction and the counting sort of the particles by
// cell.
#include "dynamic_grid.hpp"

#include <algorithm>
#include <cmath>

#include <omp.h>

#include "dualgrid/core/parallel.hpp"
#include "grid_internal.hpp"
#include "predict.hpp"

namespace dualgrid::filter {}  // namespace dualgrid::filter

namespace dualgrid::filter_ref {
using namespace ::dualgrid::filter;  // FilterParams, Measurement, SensorCoverage

using namespace detail;

void DynamicGrid::PredictAndSort(double dt, const PredictionNoise* noise) {
  const float sp = static_cast<float>(params_.process_noise_position * std::sqrt(dt));
  const float sv = static_cast<float>(params_.process_noise_velocity * std::sqrt(dt));
  const std::int64_t n = static_cast<std::int64_t>(particles_.size());
  const std::int64_t c1 = num_cells_ + 1;  // bucket num_cells_ collects particles off the grid
  const double inv_r = 1.0 / params_.resolution;
  const std::int64_t sx0 = Mod(origin_gx_, nx_), sy0 = Mod(origin_gy_, ny_);
  // Any chunking gives the same sorted order (stable): one chunk when one thread runs them all.
  const bool one_thread = OneThreadHere();
  const int chunks = one_thread ? 1 : std::clamp(omp_get_max_threads(), 1, kMaxSortChunks);
  // Blocks of cells for pass 2 (small enough to balance two threads at the paper size).
  constexpr std::int64_t kCellBlock = 1 << 10;
  const std::int64_t nblocks = (c1 + kCellBlock - 1) / kCellBlock;
  if (static_cast<std::int64_t>(hist_total_.size()) < nblocks + 1) hist_total_.resize(nblocks + 1);
  std::int64_t* block_base = hist_total_.data();
  // Counting sort, stable: particle order within a cell = order before sorting, for any chunking.
  // Pass 1 (per chunk): prediction (step 2, batch by batch while the batch is in cache), storage
  // cell of each particle and the chunk's histogram.
  const auto predict_and_count = [&](int k) {
    std::int32_t* h = hist_.data() + k * c1;
    std::fill_n(h, c1, 0);
    const std::int64_t chunk_hi = (k + 1) * n / chunks;
    for (std::int64_t b0 = k * n / chunks; b0 < chunk_hi; b0 += detail::kPredictBlock) {
      const std::int64_t b1 = std::min(chunk_hi, b0 + detail::kPredictBlock);
      detail::PredictRange(particles_, b0, b1, dt, sp, sv, cycle_params_.persistence, seed_, step_,
                           noise);
      for (std::int64_t i = b0; i < b1; ++i) {
        const double fx = std::floor(particles_.x[i] * inv_r) - static_cast<double>(origin_gx_);
        const double fy = std::floor(particles_.y[i] * inv_r) - static_cast<double>(origin_gy_);
        const bool inside = fx >= 0.0 && fy >= 0.0 && fx < nx_ && fy < ny_;  // false for NaN too
        std::int64_t c = num_cells_;
        if (inside) {
          // Storage index without integer division (hot loop): wrap once.
          std::int64_t sx = sx0 + static_cast<std::int64_t>(fx);
          std::int64_t sy = sy0 + static_cast<std::int64_t>(fy);
          if (sx >= nx_) sx -= nx_;
          if (sy >= ny_) sy -= ny_;
          c = sy * nx_ + sx;
        }
        cell_of_[i] = c;
        ++h[c];
      }
    }
  };
  // Pass 2: cell starts and per-chunk write offsets in fixed blocks of cells (integers: exact in
  // any order). Block totals first, then a serial scan over blocks, then the offsets.
  const auto block_total = [&](std::int64_t b) {
    const std::int64_t lo = b * kCellBlock, hi = std::min(c1, lo + kCellBlock);
    std::int64_t t = 0;
    for (int k = 0; k < chunks; ++k) {
      const std::int32_t* h = hist_.data() + k * c1;
      for (std::int64_t c = lo; c < hi; ++c) t += h[c];
    }
    block_base[b + 1] = t;
  };
  const auto scan_blocks = [&] {
    block_base[0] = 0;
    for (std::int64_t b = 0; b < nblocks; ++b) block_base[b + 1] += block_base[b];
    cell_start_[c1] = n;
  };
  const auto block_offsets = [&](std::int64_t b) {
    const std::int64_t lo = b * kCellBlock, hi = std::min(c1, lo + kCellBlock);
    std::int64_t run = block_base[b];
    for (std::int64_t c = lo; c < hi; ++c) {
      cell_start_[c] = run;
      for (int k = 0; k < chunks; ++k) {
        const std::int64_t t = hist_[k * c1 + c];
        hist_[k * c1 + c] = static_cast<std::int32_t>(run);
        run += t;
      }
    }
  };
  // Pass 3: each chunk's particles to their sorted slots.
  const auto scatter = [&](int k) {
    std::int32_t* h = hist_.data() + k * c1;
    for (std::int64_t i = k * n / chunks; i < (k + 1) * n / chunks; ++i) {
      sorted_.CopyFrom(particles_, i, h[cell_of_[i]]++);
    }
  };
  if (one_thread) {  // no team to build (dualgrid/core/parallel.hpp)
    for (int k = 0; k < chunks; ++k) predict_and_count(k);
    for (std::int64_t b = 0; b < nblocks; ++b) block_total(b);
    scan_blocks();
    for (std::int64_t b = 0; b < nblocks; ++b) block_offsets(b);
    for (int k = 0; k < chunks; ++k) scatter(k);
  } else {
    // One parallel region; the worksharing loops' implicit barriers order the passes.
#pragma omp parallel
    {
#pragma omp for schedule(static)
      for (int k = 0; k < chunks; ++k) predict_and_count(k);
#pragma omp for schedule(static)
      for (std::int64_t b = 0; b < nblocks; ++b) block_total(b);
#pragma omp single
      scan_blocks();
#pragma omp for schedule(static)
      for (std::int64_t b = 0; b < nblocks; ++b) block_offsets(b);
#pragma omp for schedule(static)
      for (int k = 0; k < chunks; ++k) scatter(k);
    }
  }
  sorted_current_ = true;  // sorted_ and cell_start_ bin the particles on the current cells
}

}  // namespace dualgrid::filter_ref
