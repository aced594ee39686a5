// Steps 2-3 of the cycle (docs/algorithm.md): prediction and the counting sort of the particles by
// cell.
#include "dualgrid/filter/dynamic_grid.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>

#include "grid_internal.hpp"
#include "predict.hpp"
#include "team.hpp"

namespace dualgrid::filter {

using namespace detail;

void DynamicGrid::PredictAndSort(const Team& t, std::span<const Measurement> z, double dt,
                                 const PredictionNoise* noise) {
  const float sp = static_cast<float>(params_.process_noise_position * std::sqrt(dt));
  const float sv = static_cast<float>(params_.process_noise_velocity * std::sqrt(dt));
  const std::int64_t n = static_cast<std::int64_t>(particles_.size());
  const std::int64_t c1 = num_cells_ + 1;  // bucket num_cells_ collects particles off the grid
  // Positions in grid-local metres (LocalParticles): the grid's shift of this cycle (whole cells,
  // k r) is subtracted before the motion is added.
  const float r = static_cast<float>(params_.resolution);
  const float inv_r = static_cast<float>(1.0 / params_.resolution);
  const PositionMap<float> map{static_cast<float>(dt), 1.0f, static_cast<float>(shift_gx_) * r,
                               static_cast<float>(shift_gy_) * r};
  const std::int64_t sx0 = Mod(origin_gx_, nx_), sy0 = Mod(origin_gy_, ny_);
  // Any chunking gives the same sorted order (stable): one chunk per thread.
  const int chunks = std::min(t.size, kMaxSortChunks);
  // Blocks of cells for pass 2 (small enough to balance two threads at the paper size).
  constexpr std::int64_t kCellBlock = 1 << 10;
  const std::int64_t nblocks = (c1 + kCellBlock - 1) / kCellBlock;
  assert(static_cast<std::int64_t>(hist_total_.size()) >= nblocks + 1);  // the constructor's
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
      detail::PredictRange(particles_, b0, b1, map, sp, sv, cycle_params_.persistence, seed_, step_,
                           noise);
      const float fnx = static_cast<float>(nx_), fny = static_cast<float>(ny_);
      const std::int32_t nx = nx_, ny = ny_, sx0i = static_cast<std::int32_t>(sx0),
                         sy0i = static_cast<std::int32_t>(sy0),
                         off = static_cast<std::int32_t>(num_cells_);
      for (std::int64_t i = b0; i < b1; ++i) {
        const float fx = std::floor(particles_.x[i] * inv_r),
                    fy = std::floor(particles_.y[i] * inv_r);
        const bool inside = fx >= 0.0f && fy >= 0.0f && fx < fnx && fy < fny;  // false for NaN too
        // Storage index without integer division (hot loop): wrap once.
        std::int32_t sx = sx0i + (inside ? static_cast<std::int32_t>(fx) : 0);
        std::int32_t sy = sy0i + (inside ? static_cast<std::int32_t>(fy) : 0);
        sx -= sx >= nx ? nx : 0;
        sy -= sy >= ny ? ny : 0;
        const std::int32_t c = inside ? sy * nx + sx : off;
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
  // The passes in order, each ending at a barrier; the serial scan runs beside this cycle's
  // detection tables and the copy of the field-of-view bits (Cell, ExportMasses), which nothing
  // before the cell update reads.
  ForStatic(t, chunks, predict_and_count);
  // Few blocks (the paper size: 20): their totals on the scanning thread, one barrier fewer.
  const bool few = nblocks <= 32;
  if (!few) ForStatic(t, nblocks, block_total);
  Both(
      t,
      [&] {
        if (few)
          for (std::int64_t b = 0; b < nblocks; ++b) block_total(b);
        scan_blocks();
        std::copy(mg_->view_.begin(), mg_->view_.end(), view_.begin());  // same size
      },
      [&] { DetectionTables(z); });
  ForStatic(t, nblocks, block_offsets);
  ForStatic(t, chunks, scatter);
}

}  // namespace dualgrid::filter
