// Test reference (tests/filter/test_weigh_particles.cpp): WeighParticles of commit 27f8aeb (before
// the two running minima of Nearest), namespace dualgrid::filter_ref.
// Not part of the library. Built for the library's SIMD target (tests/filter/CMakeLists.txt).
#include "weigh_particles.hpp"

#include <algorithm>

#include <hwy/contrib/math/math-inl.h>
#include <hwy/highway.h>

namespace dualgrid::filter_ref {

using namespace ::dualgrid::filter;          // WeightMode
using namespace ::dualgrid::filter::detail;  // WeighInputs, CellParticles, CellSums

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

// Nearest candidate detection of each lane's particle within the cutoff: squared distance
// [m^2] into d2, index j (or -1) into jn. Ties go to the lower index.
inline void Nearest(const WeighInputs& in, const CellParticles& c, VF x, VF y, VF& d2, VI& jn) {
  const DF df;
  const DI di;
  d2 = hn::Set(df, in.cutoff2);
  jn = hn::Set(di, -1);
  const VI minus_one = hn::Set(di, -1);
  for (const auto& range : c.cand) {
    for (std::int64_t k = range[0]; k < range[1]; ++k) {
      const VF ex = hn::Sub(hn::Set(df, in.det_x[k]), x);
      const VF ey = hn::Sub(hn::Set(df, in.det_y[k]), y);
      const VF e2 = hn::Add(hn::Mul(ex, ex), hn::Mul(ey, ey));
      const VI item = hn::Set(di, in.det_item[k]);
      const auto tie = hn::And(
          hn::Eq(e2, d2), hn::RebindMask(df, hn::And(hn::Gt(jn, minus_one), hn::Lt(item, jn))));
      const auto better = hn::Or(hn::Lt(e2, d2), tie);
      d2 = hn::IfThenElse(better, e2, d2);
      jn = hn::IfThenElse(hn::RebindMask(di, better), item, jn);
    }
  }
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

}  // namespace dualgrid::filter_ref
