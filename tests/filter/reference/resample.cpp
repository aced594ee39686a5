// Test reference (tests/filter/test_float_bound.cpp): the double filter cycle of commit 27d8ca3
// (before issue 37), namespace dualgrid::filter_ref. Not part of the library.
// Step 8 of the cycle (docs/algorithm.md): systematic resampling of persistent and new-born
// particles on the mode's weight (in dual mode w_resample = max(w_position, w_velocity), eq. 14).
#include "dynamic_grid.hpp"

#include <algorithm>
#include <vector>

#include <omp.h>

#include "dualgrid/core/parallel.hpp"
#include "dualgrid/core/random.hpp"
#include "grid_internal.hpp"

namespace dualgrid::filter {}  // namespace dualgrid::filter

namespace dualgrid::filter_ref {
using namespace ::dualgrid::filter;  // FilterParams, Measurement, SensorCoverage

using namespace detail;

namespace {

// Exclusive prefix sum over the concatenation of a[0..na) and b[0..n - na) (floats, summed in
// double) into out[0..n], with exactly the summation order of ExclusiveScan (particles.cpp: blocks
// of kScanBlock, block totals, serial scan, local scans): bit-identical to it, without
// materialising the concatenated input.
void ConcatScan(const float* a, std::int64_t na, const float* b, std::int64_t n, double* out) {
  const auto block_sum = [&](std::int64_t lo, std::int64_t hi, double acc) {
    for (std::int64_t i = lo; i < std::min(hi, na); ++i) acc += static_cast<double>(a[i]);
    for (std::int64_t i = std::max(lo, na); i < hi; ++i) acc += static_cast<double>(b[i - na]);
    return acc;
  };
  const auto block_scan = [&](std::int64_t lo, std::int64_t hi, double acc) {
    for (std::int64_t i = lo; i < std::min(hi, na); ++i) {
      out[i] = acc;
      acc += static_cast<double>(a[i]);
    }
    for (std::int64_t i = std::max(lo, na); i < hi; ++i) {
      out[i] = acc;
      acc += static_cast<double>(b[i - na]);
    }
    return acc;
  };
  const std::int64_t blocks = (n + kScanBlock - 1) / kScanBlock;
  if (blocks <= 1) {
    out[n] = block_scan(0, n, 0.0);
    return;
  }
  static thread_local std::vector<double> base;
  if (base.size() < static_cast<std::size_t>(blocks) + 1) base.resize(blocks + 1);
  double* const tot = base.data();
  ParallelFor(blocks, Schedule::kStatic, [&](std::int64_t k) {
    const std::int64_t lo = k * kScanBlock, hi = std::min(n, lo + kScanBlock);
    tot[k + 1] = block_sum(lo, hi, 0.0);
  });
  tot[0] = 0.0;
  for (std::int64_t k = 0; k < blocks; ++k) tot[k + 1] += tot[k];
  ParallelFor(blocks, Schedule::kStatic, [&](std::int64_t k) {
    const std::int64_t lo = k * kScanBlock, hi = std::min(n, lo + kScanBlock);
    block_scan(lo, hi, tot[k]);
  });
  out[n] = tot[blocks];
}

// SystematicRanges (particles.cpp) for one source: first output slot of source i. The argument
// of the ceiling lies in [-1, n] (cumulative <= total), so CeilToInt is exact.
inline std::int64_t SystematicStart(const double* cumulative, std::int64_t i, std::int64_t n_src,
                                    double scale, double u, std::int64_t n) {
  if (i == 0) return 0;
  if (i == n_src) return n;
  return std::clamp(CeilToInt(cumulative[i] * scale - u), std::int64_t{0}, n);
}

}  // namespace

void DynamicGrid::Resample() {
  const std::int64_t n_in = cell_start_[num_cells_];  // sorted persistent particles on the grid
  const std::int64_t nb = static_cast<std::int64_t>(births_.size());
  const std::int64_t n_src = n_in + nb;
  const std::int64_t n = static_cast<std::int64_t>(particles_.size());
  // Prefix sums straight from the float weights (no separate gather pass).
  ConcatScan(sorted_.weight.data(), n_in, births_.weight.data(), n_src, scan_out_.data());
  const double total = scan_out_[n_src];
  if (!(total > 0.0)) {
    // No dynamic mass anywhere: keep the particle positions (zero weight), refilled uniformly
    // from the sources so the count stays fixed.
    if (n_src == 0) {
      Initialize(EgoInput{Pose2{CellCenter({nx_ / 2, ny_ / 2}), 0.0}, Velocity::Zero()});
      return;
    }
    ParallelFor(n, Schedule::kStatic, [&](std::int64_t k) {
      const std::int64_t i = k * n_src / n;
      if (i < n_in) {
        particles_.CopyFrom(sorted_, i, k);
      } else {
        particles_.CopyFrom(births_, i - n_in, k);
      }
      particles_.weight[k] = particles_.w_position[k] = particles_.w_velocity[k] = 0.0;
    });
    return;
  }
  CounterRng rng(seed_, RngPurpose::kFilterResample, step_, 0);
  // Systematic ranges (SystematicRanges) computed inside the copy loop: source i owns output
  // slots [start(i), start(i + 1)).
  const double u = rng.Uniform();
  const double scale = static_cast<double>(n) / total;
  const double share = total / static_cast<double>(n);
  const double* const cum = scan_out_.data();
  // Contiguous source ranges per thread; each range boundary is computed once.
  const auto copy_range = [&](std::int64_t t, std::int64_t nt) {
    const std::int64_t i_lo = n_src * t / nt, i_hi = n_src * (t + 1) / nt;
    std::int64_t k1 = SystematicStart(cum, i_lo, n_src, scale, u, n);
    for (std::int64_t i = i_lo; i < i_hi; ++i) {
      const std::int64_t k0 = k1;
      k1 = SystematicStart(cum, i + 1, n_src, scale, u, n);
      if (k0 == k1) continue;
      const ParticleSet& src = i < n_in ? sorted_ : births_;
      const std::int64_t si = i < n_in ? i : i - n_in;
      // Copies carry the new equal share; w_position / w_velocity keep their ratio to the weight.
      const double ratio = share / src.weight[si];
      for (std::int64_t k = k0; k < k1; ++k) {
        particles_.CopyFrom(src, si, k);
        particles_.weight[k] = share;
        particles_.w_position[k] *= ratio;
        particles_.w_velocity[k] *= ratio;
      }
    }
  };
  if (OneThreadHere()) {
    copy_range(0, 1);
  } else {
#pragma omp parallel
    copy_range(omp_get_thread_num(), omp_get_num_threads());
  }
}

}  // namespace dualgrid::filter_ref
