// Step 8 of the cycle (docs/algorithm.md): systematic resampling of persistent and new-born
// particles on the mode's weight (in dual mode w_resample = max(w_position, w_velocity), eq. 14).
#include "dualgrid/filter/dynamic_grid.hpp"

#include <algorithm>
#include <vector>

#include "dualgrid/core/random.hpp"
#include "grid_internal.hpp"
#include "team.hpp"

namespace dualgrid::filter {

using namespace detail;

namespace {

// The exclusive prefix sums of ExclusiveScan (particles.cpp: blocks of kScanBlock, block totals,
// serial scan, local scans) over the concatenation of the persistent weights a[0..na) and the
// births' b[0..n - na) (floats, summed in double) into out[0..n]: the same summation order, so
// bit-identical to it, without materialising the concatenated input.
struct ConcatScan {
  const float *a, *b;
  std::int64_t na, n;
  double* out;
  double* tot;  // blocks() + 1 block totals

  std::int64_t blocks() const { return (n + kScanBlock - 1) / kScanBlock; }
  // acc + x[lo] + ... + x[hi - 1] over the concatenation, in order.
  double Sum(std::int64_t lo, std::int64_t hi, double acc) const {
    for (std::int64_t i = lo; i < std::min(hi, na); ++i) acc += static_cast<double>(a[i]);
    for (std::int64_t i = std::max(lo, na); i < hi; ++i) acc += static_cast<double>(b[i - na]);
    return acc;
  }
  // out[i] = the running sum before x[i], for i in [lo, hi), from acc; returns the sum after.
  double Scan(std::int64_t lo, std::int64_t hi, double acc) const {
    for (std::int64_t i = lo; i < std::min(hi, na); ++i) {
      out[i] = acc;
      acc += static_cast<double>(a[i]);
    }
    for (std::int64_t i = std::max(lo, na); i < hi; ++i) {
      out[i] = acc;
      acc += static_cast<double>(b[i - na]);
    }
    return acc;
  }
  // The whole scan by the team t; with one block, `head` is Scan(0, na, 0.0), already done.
  void Run(const Team& t, double head) const {
    const std::int64_t nbk = blocks();
    if (nbk <= 1) {
      Single(t, [&] { out[n] = Scan(na, n, head); });
      return;
    }
    ForStatic(t, nbk, [&](std::int64_t k) {
      const std::int64_t lo = k * kScanBlock, hi = std::min(n, lo + kScanBlock);
      tot[k + 1] = Sum(lo, hi, 0.0);
    });
    Single(t, [&] {
      tot[0] = 0.0;
      for (std::int64_t k = 0; k < nbk; ++k) tot[k + 1] += tot[k];
      out[n] = tot[nbk];
    });
    ForStatic(t, nbk, [&](std::int64_t k) {
      const std::int64_t lo = k * kScanBlock, hi = std::min(n, lo + kScanBlock);
      Scan(lo, hi, tot[k]);
    });
  }
};

// SystematicRanges (particles.cpp) for one source: first output slot of source i. The argument
// of the ceiling lies in [-1, n] (cumulative <= total), so CeilToInt is exact.
inline std::int64_t SystematicStart(const double* cumulative, std::int64_t i, std::int64_t n_src,
                                    double scale, double u, std::int64_t n) {
  if (i == 0) return 0;
  if (i == n_src) return n;
  return std::clamp(CeilToInt(cumulative[i] * scale - u), std::int64_t{0}, n);
}

// The systematic draw positions of one thread: sources [i_lo, i_hi) own output slots [k_lo, k_hi)
// (k_lo = Start(i_lo), k_hi = Start(i_hi)). Fills owner[k] for k in [k_lo, k_hi) with the source
// of slot k, the last i with Start(i) <= k, without a branch per source: each source's index is
// written at its first slot (a later source with the same start overwrites an earlier, empty
// one), then a running maximum fills the slots between. owner: the caller's n entries; source
// indices fit 32 bits (num_particles and num_birth are ints).
struct SystematicOwners {
  const double* cum;
  std::int64_t n_src, n;
  double scale, u;

  std::int64_t Start(std::int64_t i) const { return SystematicStart(cum, i, n_src, scale, u, n); }
  void Fill(std::int64_t i_lo, std::int64_t i_hi, std::int64_t k_lo, std::int64_t k_hi,
            std::uint32_t* owner) const {
    std::fill(owner + k_lo, owner + k_hi, static_cast<std::uint32_t>(i_lo));
    for (std::int64_t i = i_lo + 1; i < i_hi; ++i) {
      const std::int64_t k = Start(i);  // >= k_lo: starts never decrease
      if (k < k_hi) owner[k] = static_cast<std::uint32_t>(i);
    }
    for (std::int64_t k = k_lo + 1; k < k_hi; ++k) owner[k] = std::max(owner[k], owner[k - 1]);
  }
};

// out's slots [k_a, k_b) = copies of src's particles owner[k] - first, carrying the equal share;
// w_position / w_velocity keep their ratio to the weight (share / the source's weight).
void CopyOwned(const LocalParticles& src, std::int64_t first, const std::uint32_t* owner,
               std::int64_t k_a, std::int64_t k_b, double share, LocalParticles& out) {
  const float *const sx = src.x.data(), *const sy = src.y.data(), *const svx = src.vx.data(),
                     *const svy = src.vy.data(), *const sw = src.weight.data(),
                     *const swp = src.w_position.data(), *const swv = src.w_velocity.data();
  float *const x = out.x.data(), *const y = out.y.data(), *const vx = out.vx.data(),
               *const vy = out.vy.data(), *const w = out.weight.data(),
               *const wp = out.w_position.data(), *const wv = out.w_velocity.data();
  const auto share_f = static_cast<float>(share);
  for (std::int64_t k = k_a; k < k_b; ++k) {
    const std::int64_t i = static_cast<std::int64_t>(owner[k]) - first;
    x[k] = sx[i];
    y[k] = sy[i];
    vx[k] = svx[i];
    vy[k] = svy[i];
    const double ratio = share / sw[i];
    w[k] = share_f;
    wp[k] = static_cast<float>(swp[i] * ratio);
    wv[k] = static_cast<float>(swv[i] * ratio);
  }
}

}  // namespace

void DynamicGrid::ScanPersistent() {
  const std::int64_t n_in = cell_start_[num_cells_];  // sorted persistent particles on the grid
  const std::int64_t n_src = n_in + static_cast<std::int64_t>(births_.size());
  const ConcatScan scan{sorted_.weight.data(), births_.weight.data(), n_in, n_src,
                        scan_out_.data(),      scan_base_.data()};
  // One block: the persistent weights' share of the serial scan, the births' follows in
  // Resample. Several blocks: Resample does all of it with the team.
  if (scan.blocks() <= 1) scan_persistent_ = scan.Scan(0, n_in, 0.0);
}

void DynamicGrid::Resample(const Team& t) {
  const std::int64_t n_in = cell_start_[num_cells_];  // sorted persistent particles on the grid
  const std::int64_t nb = static_cast<std::int64_t>(births_.size());
  const std::int64_t n_src = n_in + nb;
  const std::int64_t n = static_cast<std::int64_t>(particles_.size());
  // Prefix sums straight from the float weights (no separate gather pass).
  const ConcatScan scan{sorted_.weight.data(), births_.weight.data(), n_in, n_src,
                        scan_out_.data(),      scan_base_.data()};
  scan.Run(t, scan_persistent_);
  const double total = scan_out_[n_src];  // every thread reads it after Run's barrier
  if (!(total > 0.0)) {
    // No dynamic mass anywhere: keep the particle positions (zero weight), refilled uniformly
    // from the sources so the count stays fixed.
    if (n_src == 0) {
      Single(t, [&] {
        InitializeOrigin(EgoInput{Pose2{CellCenter({nx_ / 2, ny_ / 2}), 0.0}, Velocity::Zero()});
      });
      SpreadParticles(t);
      return;
    }
    ForStatic(t, n, [&](std::int64_t k) {
      const std::int64_t i = k * n_src / n;
      if (i < n_in) {
        particles_.CopyFrom(sorted_, i, k);
      } else {
        particles_.CopyFrom(births_, i - n_in, k);
      }
      particles_.weight[k] = particles_.w_position[k] = particles_.w_velocity[k] = 0.0f;
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
  // Contiguous source ranges per thread of the team and their contiguous output slots; each
  // range boundary is computed once. No barrier at the end: the cycle's region ends here.
  const SystematicOwners systematic{cum, n_src, n, scale, u};
  const std::int64_t i_lo = n_src * t.id / t.size, i_hi = n_src * (t.id + 1) / t.size;
  const std::int64_t k_lo = systematic.Start(i_lo), k_hi = systematic.Start(i_hi);
  if (k_lo == k_hi) return;
  std::uint32_t* const owner = resample_owner_.data();
  systematic.Fill(i_lo, i_hi, k_lo, k_hi, owner);
  // Slots before start(n_in) copy persistent particles, the rest births.
  const std::int64_t k_mid = std::clamp(systematic.Start(n_in), k_lo, k_hi);
  CopyOwned(sorted_, 0, owner, k_lo, k_mid, share, particles_);
  CopyOwned(births_, n_in, owner, k_mid, k_hi, share, particles_);
}

}  // namespace dualgrid::filter
