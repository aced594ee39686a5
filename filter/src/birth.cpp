// Step 7 of the cycle (docs/algorithm.md): new-born particles from the birth mass (Nuss et al.'s
// birth; the paper gives it no equation), velocities from the Doppler of eq. (1).
#include "dualgrid/filter/dynamic_grid.hpp"

#include <algorithm>
#include <cmath>

#include "dualgrid/core/random.hpp"
#include "dualgrid/filter/simd_normals.hpp"
#include "grid_internal.hpp"
#include "team.hpp"

namespace dualgrid::filter {

using namespace detail;

namespace {
constexpr std::int64_t kChunksPerBlock = kScanBlock / kCellChunk;
}  // namespace

bool DynamicGrid::BirthMass(const Team& t, BirthSums& sums) {
  static_assert(BirthSums::kBlocks * kChunksPerBlock == BirthSums::kChunks);
  const std::int64_t nb = static_cast<std::int64_t>(births_.size());
  const std::int64_t nc = num_cells_;
  // Prefix sums of the birth masses with the summation order of ExclusiveScan (blocks of
  // kScanBlock), without materialising them: block totals here, running sums in DrawBirths.
  const std::int64_t blocks = (nc + kScanBlock - 1) / kScanBlock;
  // Few blocks (the paper size: 2): every thread sums them itself into its own `sums` (the same
  // sums in the same order), so no thread waits for another here. Otherwise the team shares
  // born_block_ (blocks + 1) and born_chunk_acc_.
  const bool few = blocks <= BirthSums::kBlocks;
  double* const tot = few ? sums.own_tot : born_block_.data();
  double* const chunk_acc = few ? sums.own_chunk_acc : born_chunk_acc_.data();
  sums.tot = tot;
  sums.chunk_acc = chunk_acc;
  // Most cells have no birth mass; adding +-0 leaves acc (>= +0) unchanged, so only the cells of
  // UpdateCells' per-chunk lists (non-zero mass, in cell order) are visited: same sums.
  const std::int64_t n_chunks = static_cast<std::int64_t>(born_count_.size());
  const auto block_total = [&](std::int64_t b) {
    double acc = 0.0;
    for (std::int64_t ch = b * kChunksPerBlock; ch < std::min(n_chunks, (b + 1) * kChunksPerBlock);
         ++ch) {
      const std::int64_t* list = born_cells_.data() + ch * kCellChunk;
      for (std::int32_t k = 0; k < born_count_[ch]; ++k) acc += born_[list[k]];
    }
    tot[b + 1] = acc;
  };
  const auto scan = [&] {
    tot[0] = 0.0;
    for (std::int64_t b = 0; b < blocks; ++b) tot[b + 1] += tot[b];
  };
  const auto zero_births = [&] {  // no birth mass: zero-weight births
    std::fill(births_.weight.begin(), births_.weight.end(), 0.0f);
    std::fill(births_.w_position.begin(), births_.w_position.end(), 0.0f);
    std::fill(births_.w_velocity.begin(), births_.w_velocity.end(), 0.0f);
  };
  // Running sum at each chunk start (sequential from the block base, as in DrawBirths), so that
  // the births can be generated chunk by chunk (load balance: births cluster in few blocks).
  const auto chunk_sums = [&](std::int64_t b) {
    double acc = tot[b];
    for (std::int64_t ch = b * kChunksPerBlock; ch < std::min(n_chunks, (b + 1) * kChunksPerBlock);
         ++ch) {
      chunk_acc[ch] = acc;
      const std::int64_t* list = born_cells_.data() + ch * kCellChunk;
      for (std::int32_t k = 0; k < born_count_[ch]; ++k) acc += born_[list[k]];
    }
  };
  if (few) {
    for (std::int64_t b = 0; b < blocks; ++b) block_total(b);
    scan();
  } else {
    ForStatic(t, blocks, block_total);
    Single(t, scan);  // every thread reads the same total below
  }
  const bool draw = nb > 0 && tot[blocks] > 0.0;
  if (nb > 0 && !draw) SingleNoWait(t, zero_births);  // read after a later barrier (Cycle)
  if (!draw) return false;
  if (few) {
    for (std::int64_t b = 0; b < blocks; ++b) chunk_sums(b);
  } else {
    ForStatic(t, blocks, chunk_sums);
  }
  return true;
}

void DynamicGrid::DrawBirths(const Team& t, std::span<const Measurement> z, const BirthSums& sums) {
  const std::int64_t nb = static_cast<std::int64_t>(births_.size());
  const std::int64_t nc = num_cells_;
  const std::int64_t n_chunks = static_cast<std::int64_t>(born_count_.size());
  const double* const tot = sums.tot;
  const double total = tot[(nc + kScanBlock - 1) / kScanBlock];
  // New-born particles are spread over cells in proportion to their birth mass (systematic
  // allocation, SystematicRanges); every birth carries the same mass total / num_birth.
  CounterRng offset_rng(seed_, RngPurpose::kFilterBirth, step_, 0xFFFFFFFFu);
  const double u = offset_rng.Uniform();
  const double scale = static_cast<double>(nb) / total;
  const double mass = total / static_cast<double>(nb);
  const double vmax = params_.birth_max_tangential_speed;
  const auto start = [&](std::int64_t i, double cumulative) -> std::int64_t {
    if (i == 0) return 0;
    if (i == nc) return nb;
    return std::clamp(CeilToInt(cumulative * scale - u), std::int64_t{0}, nb);
  };
  // The births' draws for all of [0, nb) first, in batches of whole lane groups: a cell gets a
  // few births, and drawing per cell would compute a full group of lanes for each (the words
  // depend on k alone: the same values). Each word is turned into the float its use takes
  // (ToUnit24, Normal2FromRaw) on lanes too: the same values as in the births' loop.
  constexpr std::int64_t kRawBatch = 256;
  float* const draw = birth_draw_.data();
  ForStatic(t, (nb + kRawBatch - 1) / kRawBatch, [&](std::int64_t i) {
    const std::int64_t k0 = i * kRawBatch, cnt = std::min(kRawBatch, nb - k0);
    // Draws 0-3 (block 0) and 4-5 (block 1) of CounterRng(seed, kFilterBirth, step, k).
    constexpr auto kPurpose = static_cast<std::uint32_t>(RngPurpose::kFilterBirth);
    std::uint32_t w[8][kRawBatch];
    detail::PhiloxLanes(seed_, kPurpose, step_, static_cast<std::uint32_t>(k0), cnt, 0, w[0], w[1],
                        w[2], w[3]);
    detail::PhiloxLanes(seed_, kPurpose, step_, static_cast<std::uint32_t>(k0), cnt, 1, w[4], w[5],
                        w[6], w[7]);
    detail::Unit24Lanes(w[0], cnt, draw + k0);
    detail::Unit24Lanes(w[1], cnt, draw + nb + k0);
    detail::Normal2Lanes(w[2], w[3], cnt, draw + 2 * nb + k0, draw + 3 * nb + k0);
    detail::Unit24Lanes(w[4], cnt, draw + 4 * nb + k0);
    detail::Unit24Lanes(w[5], cnt, draw + 5 * nb + k0);
  });  // a barrier: every draw is made before a cell reads it
  const double* const chunk_acc = sums.chunk_acc;
  ForDynamic(t, n_chunks, [&](std::int64_t ch) {
    const std::int64_t b = ch / kChunksPerBlock;
    const std::int64_t last = std::min(nc, (b + 1) * kScanBlock) - 1;
    const bool has_last = last < (ch + 1) * kCellChunk;  // the block's last cell is in this chunk
    double acc = chunk_acc[ch];
    bool last_seen = false;
    BirthFrame frame;  // the last frame used: neighbouring cells share their nearest detection
    // Inside a block a zero mass leaves the running sum unchanged: empty range. Only the cells
    // with mass and the block's last cell (where the block total takes over) can get births.
    const auto visit = [&](std::int64_t s, double born) {
      const bool block_end = s == last;
      last_seen = last_seen || block_end;
      const double cum_s = acc;
      if (born != 0.0) acc += born;
      const std::int64_t k_lo = start(s, cum_s), k_hi = start(s + 1, block_end ? tot[b + 1] : acc);
      if (k_lo == k_hi) return;
      const int j = mg_->near_det_[s];
      if (j != frame.j) frame = FrameOf(z, j, vmax);
      GenerateBirths(s, k_lo, k_hi, mass, frame);
    };
    const std::int64_t* list = born_cells_.data() + ch * kCellChunk;
    for (std::int32_t k = 0; k < born_count_[ch]; ++k) visit(list[k], born_[list[k]]);
    if (has_last && !last_seen) visit(last, 0.0);
  });
}

DynamicGrid::BirthFrame DynamicGrid::FrameOf(std::span<const Measurement> z, int j,
                                             double vmax) const {
  BirthFrame f;
  if (j < 0) return f;
  f.j = j;
  const Measurement& m = z[j];
  Vector2 los = m.position - m.sensor_position;
  const double los_n = los.norm();
  f.los = los_n > 0.0 ? Vector2(los / los_n) : Vector2(1.0, 0.0);
  f.tangent = Vector2(-f.los.y(), f.los.x());
  f.v_radial = m.radial_velocity.dot(f.los);  // signed compensated radial speed
  f.vt_max = std::min(vmax, std::sqrt(std::max(0.0, params_.max_speed * params_.max_speed -
                                                        f.v_radial * f.v_radial)));
  // doppler_fit: where the fit knows the tangential part better than the uniform draw (whose
  // standard deviation is vt_max / sqrt(3)), births draw it from the fit, but for a share kept
  // uniform (FitDetectionVelocities).
  f.fitted = params_.birth_velocity == BirthVelocity::kDopplerFit &&
             mg_->det_fit_sd_[j] < f.vt_max / std::sqrt(3.0);
  f.fit_t = f.fitted ? mg_->det_fit_t_[j] : 0.0;
  f.fit_sd = f.fitted ? mg_->det_fit_sd_[j] : 0.0;
  return f;
}

void DynamicGrid::GenerateBirths(std::int64_t s, std::int64_t k_lo, std::int64_t k_hi, double mass,
                                 const BirthFrame& f) {
  // Logical (grid-local) cell of storage index s: the unique one inside the current window.
  const std::int64_t sx = s % nx_, sy = s / nx_;
  const float lx = static_cast<float>(Mod(sx - origin_gx_, nx_));
  const float ly = static_cast<float>(Mod(sy - origin_gy_, ny_));
  const float r = static_cast<float>(params_.resolution);
  if (f.j < 0) {
    // Birth mass needs a detection nearby; only a rounding jump of the prefix sums at a block
    // boundary could land here. Keep the slots harmless (zero mass at the cell centre).
    for (std::int64_t k = k_lo; k < k_hi; ++k) {
      births_.x[k] = (lx + 0.5f) * r;
      births_.y[k] = (ly + 0.5f) * r;
      births_.vx[k] = births_.vy[k] = 0.0f;
      births_.weight[k] = births_.w_position[k] = births_.w_velocity[k] = 0.0f;
    }
    return;
  }
  const bool uniform = params_.birth_velocity == BirthVelocity::kUniform;
  const Vector2 los = f.los, tangent = f.tangent;
  const double v_radial = f.v_radial, vt_max = f.vt_max, fit_t = f.fit_t, fit_sd = f.fit_sd;
  const bool fitted = f.fitted;
  // The draws of CounterRng(seed, kFilterBirth, step, k), made by DrawBirths for every k:
  // uniforms ToUnit24 of words 0, 1, 4, 5 and the normals Normal2FromRaw of words 2, 3.
  const std::int64_t nb = static_cast<std::int64_t>(births_.size());
  const float* const u0 = birth_draw_.data();
  const float *const u1 = u0 + nb, *const g0 = u0 + 2 * nb, *const g1 = u0 + 3 * nb,
                     *const u4 = u0 + 4 * nb, *const u5 = u0 + 5 * nb;
  for (std::int64_t k = k_lo; k < k_hi; ++k) {
    births_.x[k] = (lx + u0[k]) * r;
    births_.y[k] = (ly + u1[k]) * r;
    const float n0 = g0[k], n1 = g1[k];
    Vector2 v;
    if (uniform) {
      // Uniform in the disc |v| <= max_speed (area-uniform radius): no Doppler information.
      const double speed = params_.max_speed * std::sqrt(u4[k]);
      const double angle = 2.0 * kPi * u5[k];
      v = speed * Vector2(std::cos(angle), std::sin(angle));
    } else {
      // Radial component from the Doppler, tangential one unobservable by this detection:
      // sampled uniformly, within what keeps the speed at most max_speed, or from the fit.
      // (Draw 5 and the second normal are used by doppler_fit only: doppler is unchanged.)
      double vt = vt_max * (2.0 * u4[k] - 1.0);
      if (fitted && u5[k] >= params_.birth_fit_uniform_share)
        vt = std::clamp(fit_t + fit_sd * n1, -vt_max, vt_max);
      v = (v_radial + params_.birth_sigma_radial * n0) * los + vt * tangent;
    }
    births_.vx[k] = v.x();
    births_.vy[k] = v.y();
    births_.weight[k] = births_.w_position[k] = births_.w_velocity[k] = mass;
  }
}

}  // namespace dualgrid::filter
