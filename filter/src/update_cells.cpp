// Steps 5-6 of the cycle (docs/algorithm.md): particle weights (paper eqs. 7, 8, 14) and the joint
// occupancy update (eqs. 9-12), cell by cell.
#include "dualgrid/filter/dynamic_grid.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "dualgrid/filter/weigh_particles.hpp"
#include "grid_internal.hpp"
#include "team.hpp"

namespace dualgrid::filter {

using namespace detail;

namespace {

// Two cells per operation (GCC / Clang vector extensions). Each lane is the scalar expression's
// IEEE operation, so every cell's result is bit-identical to the scalar code; written by hand
// because GCC 12 does not vectorise std::min feeding std::max ("control flow in loop").
using V2 = double __attribute__((vector_size(16)));
using M2 = std::int64_t __attribute__((vector_size(16)));  // lane masks: -1 true, 0 false
inline V2 Min(V2 a, V2 b) { return b < a ? b : a; }        // std::min(a, b) per lane
inline V2 Max(V2 a, V2 b) { return a < b ? b : a; }        // std::max(a, b) per lane

struct FastCellInputs {
  const std::int64_t* start;  // particle ranges per cell (cell_start_)
  const int* near;            // nearest detection per cell, -1 if none
  const std::uint8_t* view;   // observed / free-ray / no-return bits
  double free_mass, free_mass_no_return, static_persistence, free_decay;
};

// The update of a cell with no particle and no detection nearby: the general equations of
// UpdateCells with d_pred = 0 and occ_k = 0 (a free/static Dempster update, the whole occupied mass
// static, no dynamic or new-born mass), for cells [c_lo, c_hi). Writes the masses of those cells
// and leaves the others untouched; lists the others' offsets from c_lo in `slow` (in cell order)
// and returns their count.
std::int32_t FastCells(const FastCellInputs& in, std::int64_t c_lo, std::int64_t c_hi,
                       double* free_l, double* static_l, double* dynamic_l, double* born_l,
                       std::int32_t* slow) {
  std::int32_t n_slow = 0;
  // Lane values of z_free (eq. 3 with occ_k = 0): observed on a free ray -> free_mass, observed
  // without a return -> free_mass_no_return, else 0.
  const auto z_free = [&](std::int64_t s) {
    const std::uint8_t v = in.view[s];
    if (!(v & kObserved)) return 0.0;
    return (v & kFreeRay) ? in.free_mass : (v & kNoReturn) ? in.free_mass_no_return : 0.0;
  };
  const auto fast = [&](std::int64_t s) {
    return in.start[s] == in.start[s + 1] && in.near[s] < 0;
  };
  for (std::int64_t s = c_lo; s < c_hi; s += 2) {
    // An odd last cell fills both lanes (the same inputs, the same result written twice).
    const std::int64_t s1 = s + 1 < c_hi ? s + 1 : s;
    const bool f0 = fast(s), f1 = fast(s1);
    slow[n_slow] = static_cast<std::int32_t>(s - c_lo);
    n_slow += f0 ? 0 : 1;
    slow[n_slow] = static_cast<std::int32_t>(s1 - c_lo);
    n_slow += f1 || s1 == s ? 0 : 1;
    const V2 zf = {z_free(s), z_free(s1)};
    const V2 st = {static_l[s], static_l[s1]}, fr = {free_l[s], free_l[s1]};
    const V2 s_pred = Min(in.static_persistence * st, V2{1.0, 1.0});
    const V2 f_pred = Max(V2{0.0, 0.0}, Min(in.free_decay * fr, 1.0 - s_pred));
    const V2 u_pred = Max(V2{0.0, 0.0}, 1.0 - (0.0 + s_pred) - f_pred);
    const V2 norm0 = 1.0 / (1.0 - s_pred * zf);
    const V2 nf = (f_pred + u_pred * zf) * norm0;
    const V2 ns = s_pred * (1.0 - zf) * norm0;
    // Selects, not branches: fast and other cells interleave wherever particles are.
    const M2 keep = {f0 ? 0 : -1, f1 ? 0 : -1};
    const V2 dyn = {dynamic_l[s], dynamic_l[s1]}, born = {born_l[s], born_l[s1]};
    const V2 free_new = keep ? fr : nf, static_new = keep ? st : ns;
    const V2 dyn_new = keep ? dyn : V2{0.0, 0.0}, born_new = keep ? born : V2{0.0, 0.0};
    free_l[s] = free_new[0];
    free_l[s1] = free_new[1];
    static_l[s] = static_new[0];
    static_l[s1] = static_new[1];
    dynamic_l[s] = dyn_new[0];
    dynamic_l[s1] = dyn_new[1];
    born_l[s] = born_new[0];
    born_l[s1] = born_new[1];
  }
  return n_slow;
}

// A single mode's other weight `w` (w_velocity in position mode, w_position in velocity mode),
// normalised in double exactly as ScalarNormalise does, for a cell whose factor for it does not
// fit in float: literal, rho_p w / sum (that weight is not in q_norm); per cell, rho_p w / sum,
// or rho_p m / fast_mass without a sum. Particles with weight 0 are left as they are.
void OtherWeight(const CellParticles& c, float* w, bool literal, double q_norm, double rho_p,
                 double sum, double fast_mass) {
  for (std::int64_t i = c.lo; i < c.hi; ++i) {
    if (c.weight[i] == 0.0f) continue;
    if (literal)
      w[i] = static_cast<float>(q_norm > 0.0 && sum > 0.0 ? rho_p * (w[i] / sum) : 0.0);
    else
      w[i] = static_cast<float>(sum > 0.0 ? rho_p * w[i] / sum : rho_p * c.weight[i] / fast_mass);
  }
}

}  // namespace

void DynamicGrid::DetectionTables(std::span<const Measurement> z) {
  const FilterParams& p = cycle_params_;
  const MeasurementGrid& mg = *mg_;
  const int nz = static_cast<int>(z.size());
  // Per detection: f_v of the static hypothesis (v = 0; the same in both likelihood forms, since a
  // zero velocity has no line-of-sight component either).
  const double inv_2v2 = 0.5 / (p.sigma_v * p.sigma_v);
  for (int j = 0; j < nz; ++j)
    det_fv0_[j] = ExpUnder(-z[j].radial_velocity.squaredNorm() * inv_2v2);
  // radial_fit: per detection 1 / (2 (sigma_v^2 + s_t^2)) of the tangential term, 0 where no fit.
  const bool radial_fit = p.velocity_likelihood == VelocityLikelihood::kRadialFit;
  if (radial_fit) {
    for (int j = 0; j < nz; ++j) {
      const double s2 = p.sigma_v * p.sigma_v + mg.det_fit_sd_[j] * mg.det_fit_sd_[j];
      det_fit_k_[j] = std::isfinite(s2) ? 0.5 / s2 : 0.0;
    }
    // The static hypothesis (v = 0) is scored by the same f_v: under radial_fit its tangential
    // part 0 against the fit's v_t as well, so a fitted crossing car is not taken for static.
    for (int j = 0; j < nz; ++j)
      if (det_fit_k_[j] > 0.0)
        det_fv0_[j] *= ExpUnder(-mg.det_fit_t_[j] * mg.det_fit_t_[j] * det_fit_k_[j]);
  }
  // Nine float columns (PrepareCycle sized them): candidate-order x, y [m, grid-local]; per
  // detection u0, u1, u2, fit_k, fit_t, vr_x, vr_y (WeighInputs).
  const std::size_t rows = det_f_.size() / 9;
  float* col[9];
  for (std::size_t c = 0; c < 9; ++c) col[c] = det_f_.data() + c * rows;
  const double r = params_.resolution;
  const std::int64_t placed = mg.bucket_start_[static_cast<std::size_t>(mg.nbx_) * mg.nby_];
  const double x0 = static_cast<double>(origin_gx_) * r, y0 = static_cast<double>(origin_gy_) * r;
  // The detections the measurement grid placed, in grid-local metres as the particles.
  candidates_.Fill(mg.det_x_.data(), mg.det_y_.data(), mg.bucket_items_.data(), placed, x0, y0,
                   col[0], col[1]);
  for (int j = 0; j < nz; ++j) {
    col[2][j] = static_cast<float>(mg.det_los_[3 * j]);
    col[3][j] = static_cast<float>(mg.det_los_[3 * j + 1]);
    col[4][j] = static_cast<float>(mg.det_los_[3 * j + 2]);
    col[5][j] = radial_fit ? static_cast<float>(det_fit_k_[j]) : 0.0f;
    col[6][j] = radial_fit ? static_cast<float>(mg.det_fit_t_[j]) : 0.0f;
    col[7][j] = static_cast<float>(z[j].radial_velocity.x());
    col[8][j] = static_cast<float>(z[j].radial_velocity.y());
  }
}

detail::WeighInputs DynamicGrid::WeighTables() const {
  const FilterParams& p = cycle_params_;
  const std::size_t rows = det_f_.size() / 9;
  const float* col[9];
  for (std::size_t c = 0; c < 9; ++c) col[c] = det_f_.data() + c * rows;
  const bool radial_fit = p.velocity_likelihood == VelocityLikelihood::kRadialFit;
  WeighInputs in;
  const double cutoff = p.cutoff_sigmas * p.sigma_f;
  in.inv_2sf2 = static_cast<float>(0.5 / (p.sigma_f * p.sigma_f));
  in.cutoff2 = static_cast<float>(cutoff * cutoff);
  in.inv_2v2 = static_cast<float>(0.5 / (p.sigma_v * p.sigma_v));
  in.keep = static_cast<float>(1.0 - p.decay_eps);
  in.slow2 = static_cast<float>(p.static_speed * p.static_speed);
  in.mode = p.mode;
  in.radial = p.velocity_likelihood != VelocityLikelihood::kVector;
  in.radial_fit = radial_fit;
  in.det_x = col[0];
  in.det_y = col[1];
  in.det_item = candidates_.items();
  in.u0 = col[2];
  in.u1 = col[3];
  in.u2 = col[4];
  in.fit_k = col[5];
  in.fit_t = col[6];
  in.vr_x = col[7];
  in.vr_y = col[8];
  return in;
}
namespace {

// The per-cycle inputs of UpdateCells' slow cells (UpdateCells fills them).
struct UpdateInputs {
  const FilterParams* p;  // cycle_params_
  const Measurement* z;
  LocalParticles* q;  // sorted_
  const std::int64_t* start;
  const int* near;  // nearest detection per cell, -1 if none
  const double* near_d2;
  const std::uint8_t* view;
  const double* fv0;  // per detection: f_v of the static hypothesis (DetectionTables)
  double inv_2sf2, inv_sd2, inv_sv2, keep, max_speed2;
  bool literal_norm, keep_prediction;
  const CandidateIndex* candidates;
  WeighInputs weigh;
  float inv_r, fnx, fny;  // the sort's cell arithmetic (PredictAndSort), the last cell
  double *free_l, *static_l, *dynamic_l, *born_l;
};

// A slow cell between the stages of its update (Prior, Weigh, Posterior).
struct SlowCell {
  std::int64_t s, lo, hi;
  int j;  // nearest detection or -1
  bool observed;
  double cap, s_pred, o_pred, occ_k, static_k, o_up, f_up;
  CellSums sums;
};

// Eqs. (10-12) for one cell's particles in double, one particle at a time: the path of cells
// whose per-cell factors (UpdateCells) do not fit in float.
void ScalarNormalise(const FilterParams& p, const CellParticles& c, bool literal_norm,
                     bool fell_back, double q_norm, double scale, double rho_p, double sum_pos,
                     double sum_vel, double fast_mass) {
  const auto mode_factor = [&](double lp, double lv) {
    return p.mode == WeightMode::kPosition   ? lp
           : p.mode == WeightMode::kVelocity ? lv
                                             : std::max(lp, lv);  // eq. (14)
  };
  if (literal_norm) {
    // Eq. (12): w_k / q_norm, so the weights sum to rho_p. Both weights scale together (their
    // ratio is the dual state); after a fall-back the masses stand in for the zero weights.
    // A single mode's other weight is not in q_norm and would drift without bound (float
    // overflow): it is normalised on its own to rho_p, as in the per-cell form.
    // (w * scale) / q_norm, in this order: with q_norm subnormal, scale / q_norm alone would
    // overflow to inf (and 0 * inf = NaN); each w <= the unscaled q_norm, so the result is
    // <= 1. The other weight's share is w / sum <= 1, times rho_p.
    const bool own_p = fell_back || p.mode != WeightMode::kVelocity;
    const bool own_v = fell_back || p.mode != WeightMode::kPosition;
    const auto norm = [&](double w, bool own, double sum) {
      if (!(q_norm > 0.0)) return 0.0;
      if (own) return w * scale / q_norm;
      return sum > 0.0 ? rho_p * (w / sum) : 0.0;
    };
    for (std::int64_t i = c.lo; i < c.hi; ++i) {
      if (c.weight[i] == 0.0) continue;
      const double wp = fell_back ? c.weight[i] : c.w_position[i];
      const double wv = fell_back ? c.weight[i] : c.w_velocity[i];
      c.w_position[i] = static_cast<float>(norm(wp, own_p, sum_pos));
      c.w_velocity[i] = static_cast<float>(norm(wv, own_v, sum_vel));
      c.weight[i] = static_cast<float>(norm(mode_factor(wp, wv), true, 0.0));
    }
  }

  // --- Per cell: normalise weights so that they sum to rho_p; w_resample by mode. ---
  double sum_res = 0.0;
  for (std::int64_t i = c.lo; i < c.hi && !literal_norm; ++i) {
    if (c.weight[i] == 0.0) continue;
    const double m = c.weight[i];
    const double wp = sum_pos > 0.0 ? rho_p * c.w_position[i] / sum_pos : rho_p * m / fast_mass;
    const double wv = sum_vel > 0.0 ? rho_p * c.w_velocity[i] / sum_vel : rho_p * m / fast_mass;
    c.w_position[i] = wp;
    c.w_velocity[i] = wv;
    const double wr = mode_factor(wp, wv);  // w_resample
    c.weight[i] = wr;
    sum_res += wr;
  }
  if (sum_res > 0.0 && !literal_norm) {
    const double k = rho_p / sum_res;
    for (std::int64_t i = c.lo; i < c.hi; ++i) c.weight[i] = static_cast<float>(c.weight[i] * k);
  }
}

// The cell's particles into cp, no candidate ranges (Weigh adds them; cand is left as it is, not
// cleared: only the first `ranges` are read).
void SetParticles(const UpdateInputs& u, const SlowCell& c, CellParticles& cp) {
  LocalParticles& q = *u.q;
  cp.x = q.x.data();
  cp.y = q.y.data();
  cp.vx = q.vx.data();
  cp.vy = q.vy.data();
  cp.weight = q.weight.data();
  cp.w_position = q.w_position.data();
  cp.w_velocity = q.w_velocity.data();
  cp.lo = c.lo;
  cp.hi = c.hi;
  cp.ranges = 0;
  cp.observed = c.observed;
  cp.cap = static_cast<float>(c.cap);
  cp.wcap = static_cast<float>(u.literal_norm ? c.cap : 1.0);
}

// Stage 1 of a slow cell (UpdateCells): the predicted masses, the measurement's masses and their
// Dempster fusion (o_up, f_up).
void Prior(const UpdateInputs& u, std::int64_t s, SlowCell& c) {
  const FilterParams& p = *u.p;
  const std::int64_t lo = u.start[s], hi = u.start[s + 1];
  const std::uint8_t view = u.view[s];
  const bool observed = (view & kObserved) != 0;
  const double inv_2sf2 = u.inv_2sf2, inv_sd2 = u.inv_sd2, inv_sv2 = u.inv_sv2;

  // --- Prediction: predicted masses (dynamic = sum of persistent particle weights). ---
  double d_pred = 0.0;
  for (std::int64_t i = lo; i < hi; ++i) d_pred += u.q->weight[i];
  const double cap = d_pred > 1.0 ? 1.0 / d_pred : 1.0;  // dynamic mass is a probability
  d_pred *= cap;
  const double s_pred = std::min(p.static_persistence * u.static_l[s], 1.0 - d_pred);
  const double f_pred = std::max(0.0, std::min(p.free_decay * u.free_l[s], 1.0 - d_pred - s_pred));
  const double o_pred = d_pred + s_pred;
  const double u_pred = std::max(0.0, 1.0 - o_pred - f_pred);

  // --- Measurement grid: occupied (f_d, eq. 2), static (eq. 4), free (eq. 3 on rays). ---
  double occ_k = 0.0, static_k = 0.0;
  const int j = u.near[s];
  if (j >= 0) {
    const double d2 = u.near_d2[s];
    occ_k = std::exp(-d2 * inv_2sf2);
    static_k = ExpUnder(-0.5 * (d2 * inv_sd2 + u.z[j].radial_velocity.squaredNorm() * inv_sv2));
  }
  const double z_occ = p.occupied_mass * occ_k;
  double z_free = 0.0;
  if (observed) {
    if (view & kFreeRay) {
      z_free = p.free_mass * (1.0 - occ_k);
    } else if (view & kNoReturn) {
      z_free = p.free_mass_no_return * (1.0 - occ_k);
    }
  }
  const double z_unk = 1.0 - z_occ - z_free;

  // --- Temporal fusion (Dempster's rule on {free, occupied}). ---
  const double conflict = o_pred * z_free + f_pred * z_occ;
  const double norm = 1.0 / (1.0 - conflict);
  double o_up = (o_pred * (z_occ + z_unk) + u_pred * z_occ) * norm;
  double f_up = (f_pred * (z_free + z_unk) + u_pred * z_free) * norm;
  if (o_up + f_up > 1.0) {  // rounding only
    const double k = 1.0 / (o_up + f_up);
    o_up *= k;
    f_up *= k;
  }
  c.s = s;
  c.lo = lo;
  c.hi = hi;
  c.j = j;
  c.observed = observed;
  c.cap = cap;
  c.s_pred = s_pred;
  c.o_pred = o_pred;
  c.occ_k = occ_k;
  c.static_k = static_k;
  c.o_up = o_up;
  c.f_up = f_up;
}

// Stage 2: the particle weights, eqs. (7) and (8), unnormalised (SIMD lanes: WeighParticles),
// over the cell's candidate detections (CandidateIndex: the bucket rows around the cell of its
// first particle). A cell without particles has zero sums (as WeighParticles would return).
void Weigh(const UpdateInputs& u, SlowCell& c) {
  c.sums = CellSums{};
  if (c.hi == c.lo) return;
  CellParticles cp;
  SetParticles(u, c, cp);
  const float cx = std::clamp(std::floor(u.q->x[c.lo] * u.inv_r), 0.0f, u.fnx);
  const float cy = std::clamp(std::floor(u.q->y[c.lo] * u.inv_r), 0.0f, u.fny);
  cp.ranges = u.candidates->Ranges(static_cast<int>(cx), static_cast<int>(cy), cp.cand);
  c.sums = WeighParticles(u.weigh, cp);
}

// Eqs. (10-12) for the particles of a slow cell with particles (Posterior's factors): on SIMD
// lanes (NormaliseWeights) with per-cell factors, where they are finite in float; else (rare: tiny
// sums) the double path.
void NormaliseParticles(const UpdateInputs& u, const SlowCell& c, bool fell_back, double q_norm,
                        double scale, double rho_p) {
  const FilterParams& p = *u.p;
  const bool literal_norm = u.literal_norm;
  const double sum_pos = c.sums.sum_pos, sum_vel = c.sums.sum_vel, fast_mass = c.sums.fast_mass;
  CellParticles cp;
  SetParticles(u, c, cp);
  NormaliseFactors nf;
  nf.literal = literal_norm;
  nf.mode = p.mode;
  double kp, kv, kw = 0.0;
  if (literal_norm) {
    // Own weights w * scale / q_norm; with scale != 1 the unscaled q_norm is subnormal and
    // every float weight below it is 0, so the factor is 0 (not scale / q_norm = inf).
    const double own = q_norm > 0.0 && scale == 1.0 ? 1.0 / q_norm : 0.0;
    const bool own_p = fell_back || p.mode != WeightMode::kVelocity;
    const bool own_v = fell_back || p.mode != WeightMode::kPosition;
    nf.mass_p = nf.mass_v = fell_back;
    kp = own_p ? own : (q_norm > 0.0 && sum_pos > 0.0 ? rho_p / sum_pos : 0.0);
    kv = own_v ? own : (q_norm > 0.0 && sum_vel > 0.0 ? rho_p / sum_vel : 0.0);
    kw = own;
  } else {
    nf.mass_p = !(sum_pos > 0.0);
    nf.mass_v = !(sum_vel > 0.0);
    kp = rho_p / (nf.mass_p ? fast_mass : sum_pos);
    kv = rho_p / (nf.mass_v ? fast_mass : sum_vel);
  }
  // A factor out of float's range matters only for a weight the mode resamples on: a single
  // mode's other weight is then normalised in double (OtherWeight) and the mode's own weights
  // take the lanes as everywhere else, so that a mode's results never depend on the
  // likelihood of the weight it does not use (docs/algorithm.md, "Float state").
  constexpr double kFloatMax = std::numeric_limits<float>::max();
  const bool fits_p = std::abs(kp) <= kFloatMax, fits_v = std::abs(kv) <= kFloatMax;
  const bool uses_p = p.mode != WeightMode::kVelocity, uses_v = p.mode != WeightMode::kPosition;
  if ((uses_p && !fits_p) || (uses_v && !fits_v)) {
    ScalarNormalise(p, cp, literal_norm, fell_back, q_norm, scale, rho_p, sum_pos, sum_vel,
                    fast_mass);
  } else {
    if (!fits_p) OtherWeight(cp, cp.w_position, literal_norm, q_norm, rho_p, sum_pos, fast_mass);
    if (!fits_v) OtherWeight(cp, cp.w_velocity, literal_norm, q_norm, rho_p, sum_vel, fast_mass);
    nf.store_p = fits_p;
    nf.store_v = fits_v;
    nf.kp = fits_p ? static_cast<float>(kp) : 0.0f;
    nf.kv = fits_v ? static_cast<float>(kv) : 0.0f;
    nf.kw = static_cast<float>(kw);
    const double sum_res = NormaliseWeights(nf, cp);
    if (sum_res > 0.0 && !literal_norm) ScaleWeights(static_cast<float>(rho_p / sum_res), cp);
  }
}

// Stage 3: the joint normalisation of the occupied mass (eqs. 9-12), the particles' weights
// normalised, the cell's layers written. Returns true if the cell got birth mass.
bool Posterior(const UpdateInputs& u, const SlowCell& c) {
  const FilterParams& p = *u.p;
  const std::int64_t s = c.s, lo = c.lo, hi = c.hi;
  const int j = c.j;
  const bool observed = c.observed;
  const double s_pred = c.s_pred, o_pred = c.o_pred, occ_k = c.occ_k, static_k = c.static_k;
  const double o_up = c.o_up;
  double f_up = c.f_up;
  const double keep = u.keep, max_speed2 = u.max_speed2;
  const bool literal_norm = u.literal_norm, keep_prediction = u.keep_prediction;
  const CellSums& sums = c.sums;
  const double slow_mass = sums.slow_mass, fast_mass = sums.fast_mass;
  const double sum_mode = sums.sum_mode;
  double a_dyn = sums.a_dyn;
  const auto mode_factor = [&](double lp, double lv) {
    return p.mode == WeightMode::kPosition   ? lp
           : p.mode == WeightMode::kVelocity ? lv
                                             : std::max(lp, lv);  // eq. (14)
  };
  // The static hypothesis is scored like a particle with v = 0 at the cell centre.
  double ls_pos = keep, ls_vel = keep;
  if (j >= 0 || observed) {
    const double fv0 = j >= 0 ? u.fv0[j] : 0.0;
    ls_pos = occ_k * keep;
    ls_vel = occ_k * fv0 + (1.0 - occ_k) * keep;
  }
  const double l_static = mode_factor(ls_pos, ls_vel);

  // --- Joint normalisation of the occupied mass (eqs. 9-12 on o_up). ---
  double a_static = (s_pred + slow_mass) * l_static + p.static_gain * p.occupied_mass * static_k;
  // No birth hypothesis from a detection no road object could produce (|v_r| > max_speed):
  // such returns are clutter; their occupied mass stays unassigned (unknown).
  const bool plausible = j < 0 || u.z[j].radial_velocity.squaredNorm() <= max_speed2;
  double a_birth = plausible ? p.birth_probability * occ_k * (1.0 - o_pred) : 0.0;
  // Literal eqs. (9)-(12): the particles enter with their own accumulated weights.
  if (literal_norm) a_dyn = sum_mode;
  bool fell_back = false;
  if (keep_prediction && a_static + a_dyn + a_birth <= 0.0) {
    // Every hypothesis got zero likelihood (e.g. position weights far from all detections):
    // the measurement cannot arbitrate, so the predicted split is kept. (Literal eq. (7)
    // instead lets the occupied mass become unknown: zero_likelihood = literal.)
    a_static = s_pred + slow_mass;
    a_dyn = fast_mass;
    fell_back = true;
  }
  // Literal: the not-occupied mass competes in the same sum (eq. 9). P_free is read as free
  // plus unknown (1 - o_up): with free alone, a particle in a never-observed cell (no free, no
  // static evidence) would make it 100 % dynamic (docs/algorithm.md, "Switches").
  double a_free = literal_norm ? std::max(0.0, 1.0 - o_up) : 0.0;
  const double free_part = a_free > 0.0 ? f_up / a_free : 0.0;  // free share of a_free
  double q_norm = a_free + a_static + a_dyn + a_birth;
  // Subnormal likelihoods (e.g. a static mass decayed to 5e-324 and nothing else) lose their
  // precision in o_up * a / q_norm: the product rounds up to the smallest subnormal and the
  // share comes out as o_up * 1, breaking F + S <= 1 (found by the soak test,
  // docs/reliability.md). Scaling all three by 2^600 is exact and restores full precision;
  // normal values are untouched, so results elsewhere stay bit-identical.
  double scale = 1.0;
  if (q_norm > 0.0 && q_norm < std::numeric_limits<double>::min()) {
    constexpr double kScale = 0x1p600;
    scale = kScale;
    a_free *= kScale;
    a_static *= kScale;
    a_dyn *= kScale;
    a_birth *= kScale;
    q_norm = a_free + a_static + a_dyn + a_birth;
  }
  // Per cell: the shares of o_up; literal: the shares of 1 (eqs. 10-12).
  const double share = literal_norm ? 1.0 : o_up;
  double s_up = 0.0, rho_p = 0.0, rho_b = 0.0;
  if (q_norm > 0.0) {
    s_up = share * a_static / q_norm;
    rho_p = share * a_dyn / q_norm;
    rho_b = share * a_birth / q_norm;
    if (literal_norm) f_up = free_part * a_free / q_norm;
  }
  // Eqs. (10-12) for the particles.
  if (hi > lo) NormaliseParticles(u, c, fell_back, q_norm, scale, rho_p);
  u.free_l[s] = f_up;
  u.static_l[s] = s_up;
  // Reported dynamic mass: persistent particles only. New-born mass is occupied mass whose
  // motion no prediction has confirmed yet; counting it as dynamic would mark every new
  // detection with a Doppler (clutter included) dynamic at once. It stays in the unknown share
  // of the cell until its particles survive a cycle (docs/algorithm.md, step 5).
  u.dynamic_l[s] = rho_p;
  u.born_l[s] = rho_b;
  return rho_b != 0.0;
}

}  // namespace

void DynamicGrid::UpdateCells(const Team& team, std::span<const Measurement> z) {
  // This cycle's factors (persistence, decay, birth probability scaled to dt).
  const FilterParams& p = cycle_params_;
  const MeasurementGrid& mg = *mg_;
  UpdateInputs u;
  u.p = &p;
  u.z = z.data();
  u.q = &sorted_;
  u.start = cell_start_.data();
  u.near = mg.near_det_.data();
  u.near_d2 = mg.near_d2_.data();
  u.view = mg.view_.data();
  u.fv0 = det_fv0_.data();
  u.inv_2sf2 = 0.5 / (p.sigma_f * p.sigma_f);
  u.inv_sd2 = 1.0 / (p.sigma_static_distance * p.sigma_static_distance);
  u.inv_sv2 = 1.0 / (p.sigma_static_velocity * p.sigma_static_velocity);
  u.keep = 1.0 - p.decay_eps;
  u.max_speed2 = p.max_speed * p.max_speed;
  u.literal_norm = p.normalisation == Normalisation::kLiteral;
  u.keep_prediction = p.zero_likelihood == ZeroLikelihood::kKeepPrediction;
  u.candidates = &candidates_;
  u.weigh = WeighTables();
  u.inv_r = static_cast<float>(1.0 / params_.resolution);
  u.fnx = static_cast<float>(nx_ - 1);
  u.fny = static_cast<float>(ny_ - 1);
  u.free_l = free_.data();
  u.static_l = static_.data();
  u.dynamic_l = dynamic_.data();
  u.born_l = born_.data();
  const double fm = p.free_mass * (1.0 - 0.0), fm_nr = p.free_mass_no_return * (1.0 - 0.0);
  const FastCellInputs fast_in{u.start,     u.near, u.view, fm, fm_nr, p.static_persistence,
                               p.free_decay};
  // Blocks of cells dealt round robin over the team: the same block goes to the same thread every
  // cycle (its cells stay in that core's cache; dynamic scheduling moved them between cores, which
  // cost more than it balanced: docs/performance.md, round 3), and neighbouring blocks, where the
  // particles cluster, go to different threads. Every value is computed by one thread from the
  // same inputs, so results do not depend on the thread count.
  const std::int64_t chunks = (num_cells_ + kCellChunk - 1) / kCellChunk;
  ForRoundRobin(team, chunks, [&](std::int64_t ch) {
    const std::int64_t c_lo = ch * kCellChunk, c_hi = std::min(num_cells_, c_lo + kCellChunk);
    // Fast path (most cells): no particle, no detection (FastCells). The other cells keep their
    // values there and are updated below, which visits only them.
    std::int32_t slow[kCellChunk];
    const std::int32_t n_slow =
        FastCells(fast_in, c_lo, c_hi, u.free_l, u.static_l, u.dynamic_l, u.born_l, slow);
    // Cells with birth mass, in cell order (Birth reads only these).
    std::int64_t* const born_list = born_cells_.data() + c_lo;
    std::int32_t n_born = 0;
    // The slow cells, one at a time through the stages of their update.
    for (std::int32_t t = 0; t < n_slow; ++t) {
      SlowCell cell;
      Prior(u, c_lo + slow[t], cell);
      Weigh(u, cell);
      if (Posterior(u, cell)) born_list[n_born++] = cell.s;
    }
    born_count_[ch] = n_born;
  });
}
}  // namespace dualgrid::filter
