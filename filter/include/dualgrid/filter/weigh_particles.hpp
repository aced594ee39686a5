// The per-particle part of step 5 (paper eqs. 7, 8, 14), vectorised: one cell's particles in
// float, SIMD lanes through Highway. docs/algorithm.md, "Float state". Internal to the filter
// (UpdateCells); public so that tests/filter can check it bit for bit against an earlier version.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "dualgrid/filter/params.hpp"

namespace dualgrid::filter::detail {

/// Per-cycle inputs of WeighParticles. Positions in grid-local metres (LocalParticles).
struct WeighInputs {
  float inv_2sf2 = 0;  ///< 1 / (2 sigma_f^2) [1/m^2]
  float cutoff2 = 0;   ///< (cutoff_sigmas sigma_f)^2 [m^2]
  float inv_2v2 = 0;   ///< 1 / (2 sigma_v^2) [s^2/m^2]
  float keep = 0;      ///< 1 - decay_eps
  float slow2 = 0;     ///< static_speed^2 [m^2/s^2]
  WeightMode mode = WeightMode::kDual;
  bool radial = true, radial_fit = false;
  /// Detections in candidate order k (CandidateIndex): grid-local position [m] and index j.
  const float *det_x = nullptr, *det_y = nullptr;
  const int* det_item = nullptr;
  /// Per detection index j: unit line of sight (u0, u1), signed radial speed u2 [m/s], the fit's
  /// tangential factor fit_k (1 / (2 (sigma_v^2 + s_t^2)), 0: none) and speed fit_t [m/s], the
  /// compensated radial velocity vector (vr_x, vr_y) [m/s].
  const float *u0 = nullptr, *u1 = nullptr, *u2 = nullptr, *fit_k = nullptr, *fit_t = nullptr;
  const float *vr_x = nullptr, *vr_y = nullptr;
};

/// Candidate ranges of one cell at most (CandidateIndex::Ranges).
constexpr int kMaxRanges = 9;

/// One cell's particles [lo, hi) of the sorted set (arrays as LocalParticles').
struct CellParticles {
  const float *x, *y, *vx, *vy;
  float *weight, *w_position, *w_velocity;
  std::int64_t lo, hi;
  /// The cell's candidate detections: the first `ranges` of cand, candidate-order ranges
  /// [cand[r][0], cand[r][1]) (the others are not read).
  std::int64_t cand[kMaxRanges][2];
  int ranges;
  bool observed;
  float cap;   ///< the dynamic-mass cap of the cell's weights (1 / d_pred above 1)
  float wcap;  ///< cap for the literal normalisation, 1 for the per-cell one
};

/// Sums of one cell's particle loop (as UpdateCells' eqs. 9-12 read them).
struct CellSums {
  double slow_mass = 0, fast_mass = 0, sum_pos = 0, sum_vel = 0, sum_mode = 0, a_dyn = 0;
};

/// The candidate detections of the particle weights: the detections counting-sorted into square
/// buckets of k x k cells (logical cell coordinates, k a power of two), so that the candidates of
/// a cell are one contiguous range per bucket row: every detection within the cutoff of any point
/// of the cell, plus those of the same buckets. The cell-to-bucket stencil follows the disc: a
/// bucket row g whole cells away (gap g r [m]) reaches reach[g] whole cells beyond the cell's
/// column on either side, the largest such that (reach r)^2 + (g r)^2 <= R^2, where R is the
/// cutoff plus a margin above float's rounding of the grid-local positions (docs/algorithm.md,
/// "Float state"). Which detections within the cutoff are candidates is exact; the others only
/// cost time (WeighParticles keeps the lexicographic minimum of (e2, j) below the cutoff, whatever
/// the candidates' order).
class CandidateIndex {
 public:
  /// The geometry of an nx x ny grid of resolution r [m] for a cutoff [m] and room for up to
  /// `detections`; allocates (only when growing). Throws std::invalid_argument for a grid or
  /// cutoff out of range (nx, ny < 1, r or cutoff not finite and positive).
  void Configure(int nx, int ny, double r, double cutoff, std::size_t detections);
  /// Sorts the n <= Configure's `detections` points (x0 + xd[k], y0 + yd[k]) [m, the grid's
  /// coordinates] with detection indices item[k] into the buckets: writes their grid-local float
  /// positions (xd[k] - x0 as float) in candidate order into out_x, out_y (n entries each) and the
  /// indices into items(). A point outside the grid goes to the nearest edge bucket. No
  /// allocation.
  void Fill(const double* xd, const double* yd, const int* item, std::int64_t n, double x0,
            double y0, float* out_x, float* out_y);
  /// The non-empty candidate ranges of logical cell (cx, cy) (clamped to the grid) into cand;
  /// returns their count (<= kMaxRanges).
  int Ranges(int cx, int cy, std::int64_t (*cand)[2]) const;
  /// Detection index j per candidate-order entry (Fill).
  const int* items() const { return item_.data(); }
  int bucket_cells() const { return 1 << shift_; }

 private:
  int nx_ = 1, ny_ = 1, shift_ = 0, nbx_ = 1, gap_ = 0;
  float inv_r_ = 1.0f;
  std::vector<int> reach_;            // reach[g] for g = 0 .. gap_ [cells]
  std::vector<std::int32_t> start_;   // per bucket its first entry (nbx_ * nby + 1)
  std::vector<std::int32_t> bucket_;  // per point of Fill its bucket
  std::vector<int> item_;
};

/// For each particle: m = weight * cap; below static_speed its weights become 0 (m counts as
/// slow mass); otherwise the nearest candidate detection within the cutoff (ties to the lower
/// index j), the position and velocity likelihoods lp, lv (eqs. 7, 8: decayed prior `keep`
/// where neither a detection nor the field of view scores it), weight <- m, w_position <- lp
/// w_position wcap, w_velocity <- lv w_velocity wcap. Returns the sums. The lanes' sums are added
/// in a fixed order: the result depends on the particles alone (one SIMD target per build).
CellSums WeighParticles(const WeighInputs& in, const CellParticles& c);

/// Per-cell factors of the weights' normalisation (eqs. 10-12, UpdateCells): a particle with
/// weight m != 0 and weights (wp, wv) gets sources sp = (mass_p ? m : wp), sv = (mass_v ? m : wv),
/// w_position = sp kp, w_velocity = sv kv and weight = mode(sp, sv) kw (literal) or
/// mode(w_position, w_velocity) (per cell, scaled afterwards by ScaleWeights). Particles with
/// weight 0 are left as they are. store_p / store_v false: w_position / w_velocity are left as
/// they are too (a single mode's other weight, normalised by the caller: UpdateCells).
struct NormaliseFactors {
  bool mass_p = false, mass_v = false, literal = false;
  bool store_p = true, store_v = true;
  float kp = 0, kv = 0, kw = 0;
  WeightMode mode = WeightMode::kDual;
};

/// Normalises one cell's weights (NormaliseFactors); returns the sum of the new weights (lanes in
/// a fixed order).
double NormaliseWeights(const NormaliseFactors& f, const CellParticles& c);
/// weight *= k for the cell's particles.
void ScaleWeights(float k, const CellParticles& c);

}  // namespace dualgrid::filter::detail
