// WeighParticles (weigh_particles.hpp): the particle loop of step 5 on SIMD lanes (Highway, one
// static target per build: docs/performance.md, "Issue 37", why not dynamic dispatch).
#include "dualgrid/filter/weigh_particles.hpp"

#include "dualgrid/filter/simd.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include <hwy/contrib/math/math-inl.h>
#include <hwy/highway.h>

namespace dualgrid::filter::detail {

namespace hn = hwy::HWY_NAMESPACE;

#if HWY_ARCH_X86
// The filter library is built for x86-64-v2 (filter/CMakeLists.txt): SSE4 lanes, no FMA, the same
// bits on every x86-64 CPU since 2009. A change of target changes the filter's results.
static_assert(HWY_TARGET == HWY_SSE4, "the filter's SIMD target is pinned to SSE4");
#endif

namespace {

using DF = hn::ScalableTag<float>;
using DI = hn::RebindToSigned<DF>;
using VF = hn::Vec<DF>;
using VI = hn::Vec<DI>;
constexpr std::size_t kMaxLanes = HWY_MAX_BYTES / sizeof(float);

// Lane accumulators of CellSums.
struct Acc {
  VF slow, fast, pos, vel, mode, a_dyn;
};

// Mode factor of eq. (14) per lane: lp, lv or their maximum.
inline VF ModeFactor(WeightMode mode, VF lp, VF lv) {
  return mode == WeightMode::kPosition ? lp : mode == WeightMode::kVelocity ? lv : hn::Max(lp, lv);
}

// Folds candidate (e2, item) into the running lexicographic minimum (d2, jn) of the candidates
// with e2 < cutoff2; jn = kNone (below every index) while there is none, so that a candidate at
// e2 == d2 == cutoff2 never enters.
constexpr int kNone = std::numeric_limits<int>::min();
inline void Fold(VF e2, VI item, VF& d2, VI& jn) {
  const DF df;
  const DI di;
  const auto better =
      hn::Or(hn::Lt(e2, d2), hn::And(hn::Eq(e2, d2), hn::RebindMask(df, hn::Lt(item, jn))));
  d2 = hn::IfThenElse(better, e2, d2);
  jn = hn::IfThenElse(hn::RebindMask(di, better), item, jn);
}

// Squared distance [m^2] from the lanes' particles (x, y) to the candidate at bucket order k.
inline VF Distance2(const WeighInputs& in, std::int64_t k, VF x, VF y) {
  const DF df;
  const VF ex = hn::Sub(hn::Set(df, in.det_x[k]), x);
  const VF ey = hn::Sub(hn::Set(df, in.det_y[k]), y);
  return hn::Add(hn::Mul(ex, ex), hn::Mul(ey, ey));
}

// Nearest candidate detection (CellParticles::cand) of each lane's particle within the cutoff:
// squared distance [m^2] into d2, index j (or -1) into jn. Ties go to the lower index. The result
// is the lexicographic minimum of (e2, j) over the candidates with e2 < cutoff2, which does not
// depend on the candidates' order: two running minima, over the even and the odd candidates of
// each range, merged by the same rule (half the dependency chain of one).
inline void Nearest(const WeighInputs& in, const CellParticles& c, VF x, VF y, VF& d2, VI& jn) {
  const DF df;
  const DI di;
  d2 = hn::Set(df, in.cutoff2);
  jn = hn::Set(di, kNone);
  VF d2b = d2;
  VI jnb = jn;
  for (int r = 0; r < c.ranges; ++r) {
    const std::int64_t* const range = c.cand[r];
    std::int64_t k = range[0];
    for (; k + 2 <= range[1]; k += 2) {
      Fold(Distance2(in, k, x, y), hn::Set(di, in.det_item[k]), d2, jn);
      Fold(Distance2(in, k + 1, x, y), hn::Set(di, in.det_item[k + 1]), d2b, jnb);
    }
    if (k < range[1]) Fold(Distance2(in, k, x, y), hn::Set(di, in.det_item[k]), d2, jn);
  }
  Fold(d2b, jnb, d2, jn);
  jn = hn::IfThenElse(hn::Eq(jn, hn::Set(di, kNone)), hn::Set(di, -1), jn);
}

// Squared velocity error against detection jc's Doppler, in units of sigma_v^2 times 2 inv_2v2
// (eq. 8 or its radial forms).
inline VF VelocityError(const WeighInputs& in, VF vx, VF vy, VI jc) {
  const DF df;
  if (!in.radial) {
    const VF ex = hn::Sub(vx, hn::GatherIndex(df, in.vr_x, jc));
    const VF ey = hn::Sub(vy, hn::GatherIndex(df, in.vr_y, jc));
    return hn::Add(hn::Mul(ex, ex), hn::Mul(ey, ey));
  }
  const VF u0 = hn::GatherIndex(df, in.u0, jc), u1 = hn::GatherIndex(df, in.u1, jc);
  const VF e = hn::Sub(hn::Add(hn::Mul(vx, u0), hn::Mul(vy, u1)), hn::GatherIndex(df, in.u2, jc));
  VF e2 = hn::Mul(e, e);
  if (in.radial_fit) {  // along the tangent (-u1, u0): the fit, where there is one
    const VF fk = hn::GatherIndex(df, in.fit_k, jc);
    const VF et =
        hn::Sub(hn::Sub(hn::Mul(vy, u0), hn::Mul(vx, u1)), hn::GatherIndex(df, in.fit_t, jc));
    const VF add = hn::Div(hn::Mul(hn::Mul(et, et), fk), hn::Set(df, in.inv_2v2));
    e2 = hn::Add(e2, hn::IfThenElseZero(hn::Gt(fk, hn::Zero(df)), add));
  }
  return e2;
}

// One vector of particles at p[0..lanes), of which the first `valid` count.
inline void WeighVector(const WeighInputs& in, const CellParticles& c, const float* px,
                        const float* py, const float* pvx, const float* pvy, float* pw, float* pwp,
                        float* pwv, std::size_t valid, Acc& acc) {
  const DF df;
  const DI di;
  const auto lanes = hn::FirstN(df, valid);
  const VF x = hn::LoadU(df, px), y = hn::LoadU(df, py);
  const VF vx = hn::LoadU(df, pvx), vy = hn::LoadU(df, pvy);
  const VF m = hn::Mul(hn::LoadU(df, pw), hn::Set(df, c.cap));
  const VF v2 = hn::Add(hn::Mul(vx, vx), hn::Mul(vy, vy));
  const auto slow = hn::And(lanes, hn::Lt(v2, hn::Set(df, in.slow2)));
  const auto fast = hn::AndNot(slow, lanes);
  VF d2;
  VI jn;
  Nearest(in, c, x, y, d2, jn);
  const auto has = hn::RebindMask(df, hn::Gt(jn, hn::Set(di, -1)));
  // Without a detection in any lane both likelihoods are 0 in every lane: the exps and the
  // gathers are skipped (most vectors of a sparse scene; the same values as computing them).
  VF fd = hn::Zero(df), fv = hn::Zero(df);
  if (!hn::AllFalse(df, has)) {
    const VI jc = hn::Max(jn, hn::Zero(di));
    fd = hn::IfThenElseZero(has, hn::Exp(df, hn::Neg(hn::Mul(d2, hn::Set(df, in.inv_2sf2)))));
    const VF e2v = VelocityError(in, vx, vy, jc);
    fv = hn::IfThenElseZero(has, hn::Exp(df, hn::Neg(hn::Mul(e2v, hn::Set(df, in.inv_2v2)))));
  }
  const VF keep = hn::Set(df, in.keep), one = hn::Set(df, 1.0f);
  // Unobserved and no detection: the decayed prior for both.
  const auto scored = c.observed ? hn::FirstN(df, kMaxLanes) : has;
  const VF lp = hn::IfThenElse(scored, hn::Mul(fd, keep), keep);  // eq. (7)
  const VF lv = hn::IfThenElse(scored, hn::Add(hn::Mul(fd, fv), hn::Mul(hn::Sub(one, fd), keep)),
                               keep);  // eq. (8), multiplicative blend
  const VF wcap = hn::Set(df, c.wcap);
  const VF wp = hn::IfThenElseZero(fast, hn::Mul(hn::Mul(lp, hn::LoadU(df, pwp)), wcap));
  const VF wv = hn::IfThenElseZero(fast, hn::Mul(hn::Mul(lv, hn::LoadU(df, pwv)), wcap));
  const VF mf = hn::IfThenElseZero(fast, m);
  hn::StoreU(mf, df, pw);
  hn::StoreU(wp, df, pwp);
  hn::StoreU(wv, df, pwv);
  acc.slow = hn::Add(acc.slow, hn::IfThenElseZero(slow, m));
  acc.fast = hn::Add(acc.fast, mf);
  acc.pos = hn::Add(acc.pos, wp);
  acc.vel = hn::Add(acc.vel, wv);
  acc.mode = hn::Add(acc.mode, ModeFactor(in.mode, wp, wv));
  acc.a_dyn = hn::Add(acc.a_dyn, hn::Mul(mf, ModeFactor(in.mode, lp, lv)));
}

// Copies the m < lanes floats of a vector's tail (a loop, not a library call: a cell's tail is
// 1-3 particles and sparse scenes have many such cells).
inline void CopyTail(const float* from, float* to, std::size_t m) {
  for (std::size_t k = 0; k < kMaxLanes; ++k)
    if (k < m) to[k] = from[k];
}

// Lanes of v summed in lane order, in double.
inline double LaneSum(VF v) {
  const DF df;
  alignas(64) float lanes[kMaxLanes];
  hn::Store(v, df, lanes);
  double s = 0.0;
  for (std::size_t k = 0; k < hn::Lanes(df); ++k) s += lanes[k];
  return s;
}

}  // namespace

void CandidateIndex::Configure(int nx, int ny, double r, double cutoff, std::size_t detections) {
  if (nx < 1 || ny < 1 || !(std::isfinite(r) && r > 0.0) ||
      !(std::isfinite(cutoff) && cutoff > 0.0))
    throw std::invalid_argument("CandidateIndex: grid " + std::to_string(nx) + " x " +
                                std::to_string(ny) + " cells of " + std::to_string(r) +
                                " m, cutoff " + std::to_string(cutoff) + " m out of range");
  nx_ = nx;
  ny_ = ny;
  inv_r_ = static_cast<float>(1.0 / r);
  // The margin covers float's rounding of grid-local positions (relative 2^-24 of the grid's
  // extent per coordinate, a few times over: the cells of the particles and the detections, and
  // e2 against cutoff2) with a factor of ~100 to spare.
  const double reach_m = cutoff + 1e-5 * (cutoff + (nx + ny) * r);
  gap_ = static_cast<int>(std::floor(reach_m / r));
  reach_.assign(static_cast<std::size_t>(gap_) + 1, 0);
  for (int g = 0; g <= gap_; ++g) {
    const double gy = g * r;
    reach_[g] = static_cast<int>(std::floor(std::sqrt(reach_m * reach_m - gy * gy) / r));
  }
  // Buckets of 2 x 2 cells at least (a quarter of the cells to scan per cycle), more while the
  // 2 gap_ + 3 rows of cells around a cell could touch more than kMaxRanges bucket rows.
  const int span = 2 * gap_ + 3;
  shift_ = 1;
  while ((span + (1 << shift_) - 2) / (1 << shift_) + 1 > kMaxRanges) ++shift_;
  nbx_ = ((nx - 1) >> shift_) + 1;
  const int nby = ((ny - 1) >> shift_) + 1;
  start_.resize(static_cast<std::size_t>(nbx_) * nby + 1);  // Fill clears it
  if (bucket_.size() < detections) bucket_.resize(detections);
  if (item_.size() < std::max<std::size_t>(detections, 1))
    item_.resize(std::max<std::size_t>(detections, 1));
}

void CandidateIndex::Fill(const double* xd, const double* yd, const int* item, std::int64_t n,
                          double x0, double y0, float* out_x, float* out_y) {
  const std::int32_t nb = static_cast<std::int32_t>(start_.size()) - 1;
  std::fill(start_.begin(), start_.end(), 0);
  const float fnx = static_cast<float>(nx_ - 1), fny = static_cast<float>(ny_ - 1);
  for (std::int64_t k = 0; k < n; ++k) {
    // The cell of the float position (NaN-free: clamped first), clamped to the grid.
    const float x = static_cast<float>(xd[k] - x0), y = static_cast<float>(yd[k] - y0);
    const float cx = std::clamp(std::floor(x * inv_r_), 0.0f, fnx);
    const float cy = std::clamp(std::floor(y * inv_r_), 0.0f, fny);
    const std::int32_t b = (static_cast<std::int32_t>(cy) >> shift_) * nbx_ +
                           (static_cast<std::int32_t>(cx) >> shift_);
    bucket_[k] = b;
    ++start_[b];
  }
  for (std::int32_t b = 1; b < nb; ++b) start_[b] += start_[b - 1];  // ends of the buckets
  start_[nb] = static_cast<std::int32_t>(n);
  // Backwards, each bucket's end counting down to its start: the sort is stable.
  for (std::int64_t k = n - 1; k >= 0; --k) {
    const std::int32_t at = --start_[bucket_[k]];
    out_x[at] = static_cast<float>(xd[k] - x0);
    out_y[at] = static_cast<float>(yd[k] - y0);
    item_[at] = item[k];
  }
}

int CandidateIndex::Ranges(int cx, int cy, std::int64_t (*cand)[2]) const {
  cx = std::clamp(cx, 0, nx_ - 1);
  cy = std::clamp(cy, 0, ny_ - 1);
  const int k1 = (1 << shift_) - 1;
  const int y_lo = std::max(0, cy - gap_ - 1), y_hi = std::min(ny_ - 1, cy + gap_ + 1);
  int n = 0;
  for (int by = y_lo >> shift_; by <= y_hi >> shift_; ++by) {
    // Whole cells between the cell and the bucket row's nearest cell row.
    const int c0 = by << shift_, c1 = c0 + k1;
    const int g = cy < c0 ? c0 - cy - 1 : cy > c1 ? cy - c1 - 1 : 0;
    const int rx = reach_[g] + 1;
    const int bx0 = std::max(0, cx - rx) >> shift_, bx1 = std::min(nx_ - 1, cx + rx) >> shift_;
    const std::int64_t row = static_cast<std::int64_t>(by) * nbx_;
    cand[n][0] = start_[row + bx0];
    cand[n][1] = start_[row + bx1 + 1];
    n += cand[n][1] > cand[n][0] ? 1 : 0;
  }
  return n;
}

CellSums WeighParticles(const WeighInputs& in, const CellParticles& c) {
  const DF df;
  const std::int64_t n = static_cast<std::int64_t>(hn::Lanes(df));
  const VF z = hn::Zero(df);
  Acc acc{z, z, z, z, z, z};
  std::int64_t i = c.lo;
  for (; i + n <= c.hi; i += n) {
    WeighVector(in, c, c.x + i, c.y + i, c.vx + i, c.vy + i, c.weight + i, c.w_position + i,
                c.w_velocity + i, static_cast<std::size_t>(n), acc);
  }
  if (i < c.hi) {  // the tail through lane buffers (no read past the arrays)
    const std::size_t m = static_cast<std::size_t>(c.hi - i);
    alignas(64) float buf[7][kMaxLanes] = {};
    const float* src[7] = {c.x, c.y, c.vx, c.vy, c.weight, c.w_position, c.w_velocity};
    for (int a = 0; a < 7; ++a) CopyTail(src[a] + i, buf[a], m);
    WeighVector(in, c, buf[0], buf[1], buf[2], buf[3], buf[4], buf[5], buf[6], m, acc);
    CopyTail(buf[4], c.weight + i, m);
    CopyTail(buf[5], c.w_position + i, m);
    CopyTail(buf[6], c.w_velocity + i, m);
  }
  return {LaneSum(acc.slow), LaneSum(acc.fast), LaneSum(acc.pos),
          LaneSum(acc.vel),  LaneSum(acc.mode), LaneSum(acc.a_dyn)};
}

double NormaliseWeights(const NormaliseFactors& f, const CellParticles& c) {
  const DF df;
  const std::int64_t n = static_cast<std::int64_t>(hn::Lanes(df));
  const VF kp = hn::Set(df, f.kp), kv = hn::Set(df, f.kv), kw = hn::Set(df, f.kw);
  VF sum = hn::Zero(df);
  // One vector at p[0..lanes) (weight, w_position, w_velocity), of which `valid` lanes count.
  const auto vector = [&](float* pw, float* pwp, float* pwv, std::size_t valid) {
    const VF m = hn::LoadU(df, pw), wp = hn::LoadU(df, pwp), wv = hn::LoadU(df, pwv);
    const auto live = hn::And(hn::FirstN(df, valid), hn::Ne(m, hn::Zero(df)));
    const VF sp = f.mass_p ? m : wp, sv = f.mass_v ? m : wv;
    const VF np = hn::Mul(sp, kp), nv = hn::Mul(sv, kv);
    const VF nw = f.literal ? hn::Mul(ModeFactor(f.mode, sp, sv), kw) : ModeFactor(f.mode, np, nv);
    if (f.store_p) hn::StoreU(hn::IfThenElse(live, np, wp), df, pwp);
    if (f.store_v) hn::StoreU(hn::IfThenElse(live, nv, wv), df, pwv);
    hn::StoreU(hn::IfThenElse(live, nw, m), df, pw);
    sum = hn::Add(sum, hn::IfThenElseZero(live, nw));
  };
  std::int64_t i = c.lo;
  for (; i + n <= c.hi; i += n) vector(c.weight + i, c.w_position + i, c.w_velocity + i, n);
  if (i < c.hi) {
    const std::size_t m = static_cast<std::size_t>(c.hi - i);
    alignas(64) float buf[3][kMaxLanes] = {};
    float* const dst[3] = {c.weight + i, c.w_position + i, c.w_velocity + i};
    for (int a = 0; a < 3; ++a) CopyTail(dst[a], buf[a], m);
    vector(buf[0], buf[1], buf[2], m);
    for (int a = 0; a < 3; ++a) CopyTail(buf[a], dst[a], m);
  }
  return LaneSum(sum);
}

void ScaleWeights(float k, const CellParticles& c) {
  for (std::int64_t i = c.lo; i < c.hi; ++i) c.weight[i] *= k;  // the compiler's lanes
}

}  // namespace dualgrid::filter::detail

namespace dualgrid::filter {

const char* SimdTarget() { return hwy::TargetName(HWY_TARGET); }

}  // namespace dualgrid::filter
