// Step 4a (birth_velocity: doppler_fit, velocity_likelihood: radial_fit; docs/algorithm.md
// "Births"): a detection's Doppler gives one component of its object's velocity, along its line of
// sight. The detections of one object see it along different lines of sight (other points of its
// outline, other sensors), so together they fix the whole velocity vector where those lines spread
// enough: v with u_i . v = v_r,i for every detection i near it. Fitted robustly (Tukey's biweight
// by iteratively reweighted least squares), since detections of another object, of the ground or
// clutter may lie within reach. A run of detections' fits goes two at a time, one per SIMD lane,
// and detections with equal neighbour lists share one fit (RunFits): the same bits as one
// RobustDopplerFit per detection.
#include "dualgrid/filter/doppler_fit.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cassert>
#include <cmath>
#include <cstdint>
#include <limits>

#include <hwy/highway.h>

#include "dualgrid/filter/measurement_grid.hpp"
#include "grid_internal.hpp"
#include "team.hpp"

namespace dualgrid::filter {

using namespace detail;

namespace {

constexpr int kIterations = 6;
constexpr double kTukey = 4.685;  // 95 % efficiency at Gaussian noise
constexpr double kMadToSigma = 1.4826;
// SelectRank's short path: ranks this close to its guess's count are kept in a sorted buffer.
constexpr int kNearRanks = 4;
// Bucket columns and rows of a fit's window whose gaps are tabled (reach <= 3 buckets).
constexpr int kWindow = 7;

// Solve's end: v from the sums A = (a00 a01; a01 a11), b = (b0, b1); false when A is singular.
bool SolveSums(double a00, double a01, double a11, double b0, double b1, DopplerFit* f) {
  const double det = a00 * a11 - a01 * a01;
  if (!(det > 1e-12 * (a00 + a11) * (a00 + a11))) return false;
  f->vx = (a11 * b0 - a01 * b1) / det;
  f->vy = (a00 * b1 - a01 * b0) / det;
  f->a00 = a00;
  f->a01 = a01;
  f->a11 = a11;
  return true;
}

// Solves sum_i w_i u_i u_i^T v = sum_i w_i u_i y_i; false when the lines of sight (weighted) do
// not span the plane.
bool Solve(const double* ux, const double* uy, const double* y, const double* w, int n,
           DopplerFit* f) {
  double a00 = 0.0, a01 = 0.0, a11 = 0.0, b0 = 0.0, b1 = 0.0;
  for (int i = 0; i < n; ++i) {
    a00 += w[i] * ux[i] * ux[i];
    a01 += w[i] * ux[i] * uy[i];
    a11 += w[i] * uy[i] * uy[i];
    b0 += w[i] * ux[i] * y[i];
    b1 += w[i] * uy[i] * y[i];
  }
  return SolveSums(a00, a01, a11, b0, b1, f);
}

namespace hn = hwy::HWY_NAMESPACE;
using DD = hn::ScalableTag<double>;  // the pinned SSE4 target: two lanes, no FMA

// r[i] = |u_i . v - y_i| as the scalar expression computes it, lane by lane (the same IEEE
// operations in the same order); returns how many r[i] <= bound, and in *unordered whether any is
// NaN.
int Residuals(const double* ux, const double* uy, const double* y, int n, double vx, double vy,
              double bound, double* r, bool* unordered) {
  const DD d;
  const int lanes = static_cast<int>(hn::Lanes(d));
  const auto vvx = hn::Set(d, vx), vvy = hn::Set(d, vy), vb = hn::Set(d, bound);
  auto nan = hn::Zero(d);
  std::size_t below = 0;
  int i = 0;
  for (; i + lanes <= n; i += lanes) {
    const auto e =
        hn::Sub(hn::Add(hn::Mul(hn::LoadU(d, ux + i), vvx), hn::Mul(hn::LoadU(d, uy + i), vvy)),
                hn::LoadU(d, y + i));
    const auto a = hn::Abs(e);
    hn::StoreU(a, d, r + i);
    below += hn::CountTrue(d, hn::Le(a, vb));
    nan = hn::Or(nan, hn::VecFromMask(d, hn::Ne(a, a)));
  }
  bool any_nan = !hn::AllFalse(d, hn::MaskFromVec(nan));
  for (; i < n; ++i) {
    r[i] = std::abs(ux[i] * vx + uy[i] * vy - y[i]);
    below += r[i] <= bound;
    any_nan |= std::isnan(r[i]);
  }
  *unordered = any_nan;
  return static_cast<int>(below);
}

// Tukey's weights w[i] = (1 - q^2)^2 for q = r[i] / c < 1, else 0 (lane by lane as the scalar
// expression); returns the inliers (q < 1).
int TukeyWeights(const double* r, int n, double c, double* w) {
  const DD d;
  const int lanes = static_cast<int>(hn::Lanes(d));
  const auto vc = hn::Set(d, c), one = hn::Set(d, 1.0);
  std::size_t inliers = 0;
  int i = 0;
  for (; i + lanes <= n; i += lanes) {
    const auto q = hn::Div(hn::LoadU(d, r + i), vc);
    const auto t = hn::Sub(one, hn::Mul(q, q));
    const auto in = hn::Lt(q, one);
    hn::StoreU(hn::IfThenElseZero(in, hn::Mul(t, t)), d, w + i);
    inliers += hn::CountTrue(d, in);
  }
  for (; i < n; ++i) {
    const double q = r[i] / c;
    const double t = 1.0 - q * q;
    w[i] = q < 1.0 ? t * t : 0.0;
    inliers += q < 1.0;
  }
  return static_cast<int>(inliers);
}

// Which values NearRank ranks: those >= g (the smallest first), those < g (the largest first) or
// all (the largest first).
enum class Among { kAtLeast, kBelow, kAllLargest };

// The m-th extreme (M = m + 1) of the values of a[0, n) that `among` names, of which there are
// more than m: a sorted buffer of the M extreme ones, one compare-exchange chain per value, no
// branch.
template <int M, Among kAmong>
double NearRank(const double* a, int n, double g) {
  constexpr bool kSmallest = kAmong == Among::kAtLeast;
  constexpr double kFill = kSmallest ? kInf : -kInf;
  double b[M];
  std::fill_n(b, M, kFill);
  for (int i = 0; i < n; ++i) {
    const bool in = kAmong == Among::kAtLeast ? !(a[i] < g)
                    : kAmong == Among::kBelow ? a[i] < g
                                              : true;
    double x = in ? a[i] : kFill;
    for (int l = 0; l < M; ++l) {
      const double keep = kSmallest ? std::min(b[l], x) : std::max(b[l], x);
      x = kSmallest ? std::max(b[l], x) : std::min(b[l], x);
      b[l] = keep;
    }
  }
  return b[M - 1];
}

template <Among kAmong>
double NearRank(const double* a, int n, double g, int m) {
  switch (m) {
    case 0:
      return NearRank<1, kAmong>(a, n, g);
    case 1:
      return NearRank<2, kAmong>(a, n, g);
    case 2:
      return NearRank<3, kAmong>(a, n, g);
    default:
      return NearRank<4, kAmong>(a, n, g);
  }
}

// Rank k of a[0, n) (SelectRank's preconditions) by quickselect with branch-free partitions
// (median-of-three pivots) down to a rank within kNearRanks of either end.
double QuickSelect(const double* a, int n, int k) {
  double buf[2][2][kFitMaxNeighbours];  // [pass parity][below, above the pivot]
  for (int pass = 0;; pass ^= 1) {
    if (k < kNearRanks) return NearRank<Among::kAtLeast>(a, n, -kInf, k);
    if (n - 1 - k < kNearRanks) return NearRank<Among::kAllLargest>(a, n, 0.0, n - 1 - k);
    const double x0 = a[0], x1 = a[n / 2], x2 = a[n - 1];
    const double p = std::max(std::min(x0, x1), std::min(std::max(x0, x1), x2));
    double* lo = buf[pass][0];
    double* hi = buf[pass][1];
    int nl = 0, nh = 0;
    for (int i = 0; i < n; ++i) {
      lo[nl] = a[i];
      hi[nh] = a[i];
      nl += a[i] < p;
      nh += p < a[i];
    }
    if (k < nl) {
      a = lo;
      n = nl;
    } else if (k >= n - nh) {
      k -= n - nh;
      a = hi;
      n = nh;
    } else {
      return p;  // ranks [nl, n - nh) hold p
    }
  }
}

// The median's rank of the residuals r (finite or not): the old definition, a sorted copy.
double NthElement(const double* r, int n, int k) {
  double sorted[kFitMaxNeighbours];
  std::copy_n(r, n, sorted);
  std::nth_element(sorted, sorted + k, sorted + n);
  return sorted[k];
}

// The scale max(floor, 1.4826 median) of the residuals r[0, n), of which at_floor are <=
// MadFloorBound(floor) and some NaN when `unordered`; *guess: the last median selected (updated).
double Scale(const double* r, int n, int at_floor, bool unordered, double floor, double* guess) {
  const int k = n / 2;
  if (unordered) return std::max(floor, kMadToSigma * NthElement(r, n, k));
  if (at_floor > k) return floor;  // = std::max(floor, kMadToSigma * median): median <= bound
  *guess = detail::SelectRank(r, n, k, *guess);
  return std::max(floor, kMadToSigma * *guess);
}

using D2 = hn::FixedTag<double, 2>;  // RobustDopplerFitPair's lanes: one fit each
using V2 = hn::Vec<D2>;

V2 Lanes(double a, double b) {  // (a, b)
  alignas(16) const double v[2] = {a, b};
  return hn::Load(D2(), v);
}

// Solve of two fits at once, on interleaved arrays (entry i of fit l at 2 i + l) of n entries:
// each lane adds the same IEEE products in the same order as Solve's loop, so its sums are
// bitwise Solve's. A fit with fewer entries is padded with ux = uy = y = w = +0.0: each product
// is +0.0, and adding +0.0 leaves a sum bitwise unchanged, since a sum is never -0.0 (it starts
// at +0.0 and, rounding to nearest, x + y is -0.0 only when x and y both are) and s + (+0.0) = s
// for every other s, infinities and NaN included. ok[l] false: lane l skipped (dead).
void SolvePair(const double* ux, const double* uy, const double* y, const double* w, int n,
               DopplerFit f[2], bool ok[2]) {
  const D2 d;
  V2 a00 = hn::Zero(d), a01 = hn::Zero(d), a11 = hn::Zero(d), b0 = hn::Zero(d), b1 = hn::Zero(d);
  for (int i = 0; i < 2 * n; i += 2) {
    const V2 vw = hn::Load(d, w + i), vx = hn::Load(d, ux + i), vy = hn::Load(d, uy + i);
    const V2 vv = hn::Load(d, y + i), wx = hn::Mul(vw, vx), wy = hn::Mul(vw, vy);
    a00 = hn::Add(a00, hn::Mul(wx, vx));
    a01 = hn::Add(a01, hn::Mul(wx, vy));
    a11 = hn::Add(a11, hn::Mul(wy, vy));
    b0 = hn::Add(b0, hn::Mul(wx, vv));
    b1 = hn::Add(b1, hn::Mul(wy, vv));
  }
  alignas(16) double s[5][2];
  hn::Store(a00, d, s[0]);
  hn::Store(a01, d, s[1]);
  hn::Store(a11, d, s[2]);
  hn::Store(b0, d, s[3]);
  hn::Store(b1, d, s[4]);
  for (int l = 0; l < 2; ++l)
    ok[l] = ok[l] && SolveSums(s[0][l], s[1][l], s[2][l], s[3][l], s[4][l], &f[l]);
}

using DI2 = hn::RebindToSigned<D2>;

// Per lane the count of true entries of masks accumulated by Tally (all-ones lanes: -1).
std::array<int, 2> Counts(hn::Vec<DI2> tally) {
  alignas(16) std::int64_t c[2];
  hn::Store(tally, DI2(), c);
  return {static_cast<int>(-c[0]), static_cast<int>(-c[1])};
}

hn::Vec<DI2> Tally(hn::Vec<DI2> tally, hn::Mask<D2> m) {
  return hn::Add(tally, hn::BitCast(DI2(), hn::VecFromMask(D2(), m)));
}

// Residuals of two fits at once (interleaved as SolvePair's arrays, n even; lanes as Residuals
// computes them) into r, and each lane's into rl[l] (vector stores: SelectRank's vector loads of
// them are forwarded); per lane the count of real entries <= bound and whether one is NaN. real:
// per entry and lane all-ones bits for a fit's own entries, +0.0 for padding.
void ResidualsPair(const double* ux, const double* uy, const double* y, const double* real, int n,
                   const DopplerFit f[2], double bound, double* r, double* const rl[2],
                   int below[2], bool unordered[2]) {
  assert(n % 2 == 0);
  const D2 d;
  const V2 vvx = Lanes(f[0].vx, f[1].vx), vvy = Lanes(f[0].vy, f[1].vy), vb = hn::Set(d, bound);
  auto count = hn::Zero(DI2());
  V2 nan = hn::Zero(d);
  const auto residual = [&](int i) {  // entry i / 2
    const V2 e =
        hn::Sub(hn::Add(hn::Mul(hn::Load(d, ux + i), vvx), hn::Mul(hn::Load(d, uy + i), vvy)),
                hn::Load(d, y + i));
    const V2 a = hn::Abs(e);
    hn::Store(a, d, r + i);
    const auto in = hn::MaskFromVec(hn::Load(d, real + i));
    count = Tally(count, hn::And(in, hn::Le(a, vb)));
    nan = hn::Or(nan, hn::VecFromMask(d, hn::And(in, hn::Ne(a, a))));
    return a;
  };
  for (int i = 0; i < 2 * n; i += 4) {
    const V2 a = residual(i), b = residual(i + 2);
    hn::Store(hn::InterleaveLower(d, a, b), d, rl[0] + i / 2);
    hn::Store(hn::InterleaveUpper(d, a, b), d, rl[1] + i / 2);
  }
  const std::array<int, 2> c = Counts(count);
  const std::array<int, 2> u = Counts(hn::BitCast(DI2(), nan));
  for (int l = 0; l < 2; ++l) {
    below[l] = c[l];
    unordered[l] = u[l] != 0;
  }
}

// TukeyWeights of two fits at once (lanes as TukeyWeights computes them; c: the lanes' Tukey
// constants; real as ResidualsPair's), padding entries weighted +0.0; the lanes' inliers.
void TukeyWeightsPair(const double* r, const double* real, int n, V2 c, double* w, int inliers[2]) {
  const D2 d;
  const V2 one = hn::Set(d, 1.0);
  auto count = hn::Zero(DI2());
  for (int i = 0; i < 2 * n; i += 2) {
    const V2 q = hn::Div(hn::Load(d, r + i), c);
    const V2 t = hn::Sub(one, hn::Mul(q, q));
    const auto in = hn::And(hn::MaskFromVec(hn::Load(d, real + i)), hn::Lt(q, one));
    hn::Store(hn::IfThenElseZero(in, hn::Mul(t, t)), d, w + i);
    count = Tally(count, in);
  }
  const std::array<int, 2> k = Counts(count);
  inliers[0] = k[0];
  inliers[1] = k[1];
}

// Appends to key[n, ...) the positions k in [k0, k1), in order, of the points (x[k], y[k]) within
// radius2 [m^2] of (px, py), while n < kFitMaxNeighbours and *looked < kMaxCandidates (every k
// looked at counts); returns the new n. Two points per step on lanes, each as the scalar test.
int GatherRange(const double* x, const double* y, std::int64_t k0, std::int64_t k1, double px,
                double py, double radius2, int* key, int n, int* looked) {
  const D2 d;
  const V2 vpx = hn::Set(d, px), vpy = hn::Set(d, py), vr = hn::Set(d, radius2);
  std::int64_t k = k0;
  for (; k + 2 <= k1 && n <= kFitMaxNeighbours - 2 && *looked <= kMaxCandidates - 2;
       k += 2, *looked += 2) {
    const V2 ex = hn::Sub(hn::LoadU(d, x + k), vpx), ey = hn::Sub(hn::LoadU(d, y + k), vpy);
    std::uint8_t far = 0;
    hn::StoreMaskBits(d, hn::Gt(hn::Add(hn::Mul(ex, ex), hn::Mul(ey, ey)), vr), &far);
    key[n] = static_cast<int>(k);  // written always, kept when within the radius
    n += (far & 1) == 0;
    key[n] = static_cast<int>(k + 1);
    n += (far & 2) == 0;
  }
  for (; k < k1 && n < kFitMaxNeighbours && *looked < kMaxCandidates; ++k, ++*looked) {
    const double ex = x[k] - px, ey = y[k] - py;
    key[n] = static_cast<int>(k);
    n += !(ex * ex + ey * ey > radius2);
  }
  return n;
}

// One pass over a[0, n) (no NaN) against g: the values < g counted, the smallest of those >= g
// (+inf if none) and the largest of those < g (-inf if none), on lanes.
struct Bracket {
  int below;
  double above, under;
};

Bracket BracketOf(const double* a, int n, double g) {
  const D2 d;
  const V2 vg = hn::Set(d, g), inf = hn::Set(d, kInf), minus_inf = hn::Set(d, -kInf);
  V2 above = inf, under = minus_inf;
  auto count = hn::Zero(DI2());
  int i = 0;
  for (; i + 2 <= n; i += 2) {
    const V2 v = hn::LoadU(d, a + i);
    const auto lt = hn::Lt(v, vg);
    count = Tally(count, lt);
    above = hn::Min(above, hn::IfThenElse(lt, inf, v));
    under = hn::Max(under, hn::IfThenElse(lt, v, minus_inf));
  }
  const std::array<int, 2> c = Counts(count);
  alignas(16) double hi[2], lo[2];
  hn::Store(above, d, hi);
  hn::Store(under, d, lo);
  Bracket b{c[0] + c[1], std::min(hi[0], hi[1]), std::max(lo[0], lo[1])};
  for (; i < n; ++i) {
    const bool lt = a[i] < g;
    b.below += lt;
    if (lt) b.under = std::max(b.under, a[i]);
    if (!lt) b.above = std::min(b.above, a[i]);
  }
  return b;
}

}  // namespace

namespace detail {

double MadFloorBound(double floor) {
  assert(floor >= 0.0 && std::isfinite(floor));
  const auto fits = [floor](double m) { return kMadToSigma * m <= floor; };
  double m = floor / kMadToSigma;
  while (!fits(m)) m = std::nextafter(m, 0.0);
  while (fits(std::nextafter(m, kInf))) m = std::nextafter(m, kInf);
  return m;
}

double SelectRank(const double* a, int n, int k, double guess) {
  assert(0 <= k && k < n && n <= kFitMaxNeighbours);
  const Bracket b = BracketOf(a, n, guess);
  const int below = b.below;  // values < guess
  // Rank k is the (k - below)-th smallest of the values >= guess, or the (below - 1 - k)-th
  // largest of those < guess: the first two cases (most passes) from the same pass.
  if (below == k) return b.above;
  if (below == k + 1) return b.under;
  if (below <= k && k - below < kNearRanks)
    return NearRank<Among::kAtLeast>(a, n, guess, k - below);
  if (below > k && below - 1 - k < kNearRanks)
    return NearRank<Among::kBelow>(a, n, guess, below - 1 - k);
  return QuickSelect(a, n, k);
}

// Tukey-weighted fit starting from ordinary least squares; the scale is the residuals' MAD, at
// least `floor` (the radars' noise). The median is only selected where it exceeds floor_bound
// (otherwise the scale is `floor` whatever its value), near the last one selected.
bool RobustDopplerFit(const double* ux, const double* uy, const double* y, int n, double floor,
                      double floor_bound, DopplerFit* f) {
  assert(n >= 3 && n <= kFitMaxNeighbours);
  double w[kFitMaxNeighbours], r[kFitMaxNeighbours];
  std::fill_n(w, n, 1.0);
  if (!Solve(ux, uy, y, w, n, f)) return false;
  double guess = floor_bound;  // the last median selected
  for (int it = 0; it < kIterations; ++it) {
    bool unordered = false;  // a NaN residual
    const int at_floor = Residuals(ux, uy, y, n, f->vx, f->vy, floor_bound, r, &unordered);
    f->scale = Scale(r, n, at_floor, unordered, floor, &guess);
    f->inliers = TukeyWeights(r, n, kTukey * f->scale, w);
    if (f->inliers < 3 || !Solve(ux, uy, y, w, n, f)) return false;
  }
  return true;
}

bool FitMemo::Find(const int* key, int n, bool* ok, DopplerFit* f) const {
  for (int s = 0; s < size_; ++s) {
    const Entry& e = slot_[(next_ + kSlots - 1 - s) % kSlots];  // the newest first
    if (e.n != n || !std::equal(key, key + n, e.key)) continue;
    *ok = e.ok;
    *f = e.f;
    return true;
  }
  return false;
}

void FitMemo::Add(const int* key, int n, bool ok, const DopplerFit& f) {
  assert(0 <= n && n <= kFitMaxNeighbours);
  Entry& e = slot_[next_];
  e.n = n;
  std::copy_n(key, n, e.key);
  e.ok = ok;
  e.f = f;
  next_ = (next_ + 1) % kSlots;
  size_ = std::min(size_ + 1, kSlots);
}

// RobustDopplerFit's steps on both lanes: the vector parts (sums, residuals, weights) for both,
// the median and the scale per lane (scalar, as RobustDopplerFit), a lane's work ending where its
// fit does.
void RobustDopplerFitPair(const FitInput in[2], double floor, double floor_bound, DopplerFit f[2],
                          bool ok[2], double* first_guess) {
  assert(in[0].n >= 3 && in[0].n <= kFitMaxNeighbours);
  assert(in[1].n >= 3 && in[1].n <= kFitMaxNeighbours);
  const int n = (std::max(in[0].n, in[1].n) + 1) & ~1;  // even: ResidualsPair
  alignas(16) double ux[2 * kFitMaxNeighbours], uy[2 * kFitMaxNeighbours], y[2 * kFitMaxNeighbours],
      w[2 * kFitMaxNeighbours], r[2 * kFitMaxNeighbours], real[2 * kFitMaxNeighbours],
      r0[kFitMaxNeighbours], r1[kFitMaxNeighbours];
  double* const rl[2] = {r0, r1};  // the lanes' residuals, where Scale reads them
  const double all_ones = std::bit_cast<double>(~std::uint64_t{0});
  for (int l = 0; l < 2; ++l) {
    for (int i = 0; i < n; ++i) {
      const bool own = i < in[l].n;  // else padding: +0.0 (SolvePair)
      ux[2 * i + l] = own ? in[l].ux[i] : 0.0;
      uy[2 * i + l] = own ? in[l].uy[i] : 0.0;
      y[2 * i + l] = own ? in[l].y[i] : 0.0;
      w[2 * i + l] = own ? 1.0 : 0.0;
      real[2 * i + l] = own ? all_ones : 0.0;
    }
    ok[l] = true;
  }
  SolvePair(ux, uy, y, w, n, f, ok);
  double guess[2] = {*first_guess, *first_guess};  // the lanes' last medians selected
  for (int it = 0; it < kIterations && (ok[0] || ok[1]); ++it) {
    int below[2], inliers[2];
    bool unordered[2];
    ResidualsPair(ux, uy, y, real, n, f, floor_bound, r, rl, below, unordered);
    double c[2] = {1.0, 1.0};  // a dead lane's: any value
    for (int l = 0; l < 2; ++l) {
      if (!ok[l]) continue;
      f[l].scale = Scale(rl[l], in[l].n, below[l], unordered[l], floor, &guess[l]);
      if (it == 0) *first_guess = guess[l];
      c[l] = kTukey * f[l].scale;
    }
    TukeyWeightsPair(r, real, n, Lanes(c[0], c[1]), w, inliers);
    for (int l = 0; l < 2; ++l) {
      if (!ok[l]) continue;
      f[l].inliers = inliers[l];
      ok[l] = inliers[l] >= 3;
    }
    SolvePair(ux, uy, y, w, n, f, ok);
  }
}

void RunFits::Submit(int i, int n, const double* by_key) {
  assert(0 <= i && i < kRun);
  ok_[i] = false;
  if (n < 3) return;
  Gathered& g = queue_[queued_];
  if (memo_.Find(g.key, n, &ok_[i], &fit_[i])) return;
  for (int q = 0; q < queued_; ++q) {
    if (queued_n_[q] == n && std::equal(g.key, g.key + n, queue_[q].key)) {
      assert(waiters_ < kRun);
      waiter_i_[waiters_] = i;
      waiter_of_[waiters_++] = q;
      return;
    }
  }
  for (int k = 0; k < n; ++k) {  // a fit to compute: its inputs
    const double* e = by_key + 3 * static_cast<std::ptrdiff_t>(g.key[k]);
    g.ux[k] = e[0];
    g.uy[k] = e[1];
    g.y[k] = e[2];
  }
  queued_n_[queued_] = n;
  queued_i_[queued_++] = i;
  if (queued_ == 2) FitQueued();
}

void RunFits::Finish() { FitQueued(); }

void RunFits::FitQueued() {
  DopplerFit f[2];
  bool ok[2] = {false, false};
  if (queued_ == 2) {
    const FitInput in[2] = {{queue_[0].ux, queue_[0].uy, queue_[0].y, queued_n_[0]},
                            {queue_[1].ux, queue_[1].uy, queue_[1].y, queued_n_[1]}};
    RobustDopplerFitPair(in, floor_, floor_bound_, f, ok, &first_guess_);
  } else if (queued_ == 1) {
    ok[0] = RobustDopplerFit(queue_[0].ux, queue_[0].uy, queue_[0].y, queued_n_[0], floor_,
                             floor_bound_, &f[0]);
  }
  for (int q = 0; q < queued_; ++q) {
    memo_.Add(queue_[q].key, queued_n_[q], ok[q], f[q]);
    ok_[queued_i_[q]] = ok[q];
    fit_[queued_i_[q]] = f[q];
  }
  for (int k = 0; k < waiters_; ++k) {
    ok_[waiter_i_[k]] = ok[waiter_of_[k]];
    fit_[waiter_i_[k]] = f[waiter_of_[k]];
  }
  queued_ = 0;
  waiters_ = 0;
}

}  // namespace detail

namespace {

// Distance [m] along one axis from coordinate p to bucket b of nb along it, whose axis starts at
// `origin` [m] (bucket edge 1 / inv [m]); the edge buckets reach out without end. The squared
// distance of a point to a bucket is the sum of its two axes' squared gaps.
double BucketGap(double p, int b, int nb, double origin, double inv) {
  const double edge = 1.0 / inv;
  const double lo = origin + b * edge;
  return std::max({(b == 0 ? -kInf : lo) - p, 0.0, p - (b == nb - 1 ? kInf : lo + edge)});
}

}  // namespace

namespace detail {

int GatherNeighbours(const BucketView& v, double px, double py, int bx, int by, int reach,
                     double radius2, int* key) {
  const int cx_lo = std::max(0, bx - reach), cx_hi = std::min(v.nbx - 1, bx + reach);
  const int cy_lo = std::max(0, by - reach), cy_hi = std::min(v.nby - 1, by + reach);
  // The squared gaps of the window's bucket columns and rows, once per detection (per bucket
  // beyond kWindow of them: a radius of many buckets).
  double gx2[kWindow], gy2[kWindow];
  const bool tabled = cx_hi - cx_lo < kWindow && cy_hi - cy_lo < kWindow;
  for (int cx = cx_lo; tabled && cx <= cx_hi; ++cx) {
    const double g = BucketGap(px, cx, v.nbx, v.ox, v.inv);
    gx2[cx - cx_lo] = g * g;
  }
  for (int cy = cy_lo; tabled && cy <= cy_hi; ++cy) {
    const double g = BucketGap(py, cy, v.nby, v.oy, v.inv);
    gy2[cy - cy_lo] = g * g;
  }
  const auto distance2 = [&](int cx, int cy) {  // from p to bucket (cx, cy) [m^2]
    if (tabled) return gx2[cx - cx_lo] + gy2[cy - cy_lo];
    const double gx = BucketGap(px, cx, v.nbx, v.ox, v.inv),
                 gy = BucketGap(py, cy, v.nby, v.oy, v.inv);
    return gx * gx + gy * gy;
  };
  int n = 0, looked = 0;
  for (int cy = cy_lo; cy <= cy_hi; ++cy) {
    const std::int64_t row = static_cast<std::int64_t>(cy) * v.nbx;
    for (int cx = cx_lo; cx <= cx_hi; ++cx) {
      // No neighbour can lie there (a relative margin for the rounding of BucketOf's edges).
      if (distance2(cx, cy) > radius2 * (1.0 + 1e-9)) continue;
      // A run of such buckets side by side: one range of bucket order.
      const int first = cx;
      while (cx < cx_hi && !(distance2(cx + 1, cy) > radius2 * (1.0 + 1e-9))) ++cx;
      // The first kFitMaxNeighbours within the radius of the first kMaxCandidates looked at
      // (v.x, v.y: in bucket order).
      n = GatherRange(v.x, v.y, v.start[row + first], v.start[row + cx + 1], px, py, radius2, key,
                      n, &looked);
      if (n == kFitMaxNeighbours || looked == kMaxCandidates) return n;
    }
  }
  return n;
}

}  // namespace detail

void MeasurementGrid::FitDetectionVelocities(const Team& t) {
  const std::span<const Measurement> z = z_;
  const int nz = static_cast<int>(z.size());  // det_fit_t_, det_fit_sd_: Prepare sized them
  const double radius2 = params_.doppler_fit_radius * params_.doppler_fit_radius;
  const int reach = static_cast<int>(
      std::ceil(params_.doppler_fit_radius / (bucket_cells_ * params_.resolution)));
  const double floor = params_.doppler_fit_sigma;
  const double floor_bound = MadFloorBound(floor);
  const double ox = static_cast<double>(origin_gx_) * params_.resolution;
  const double oy = static_cast<double>(origin_gy_) * params_.resolution;
  const double* const los = det_los_.data();  // ComputeLinesOfSight, this cycle
  const double* const los_b = det_los_b_.data();
  const BucketView buckets{
      det_x_.data(), det_y_.data(), bucket_start_.data(), nbx_, nby_, bucket_inv_, ox, oy};
  // Detection j's neighbours' keys into g; their count (0: not near the grid, no birth from it).
  const auto gather = [&](int j, RunFits::Gathered& g) {
    if (det_bucket_[j] < 0) return 0;
    const Position& p = z[j].position;
    const auto [bx, by] = BucketOf(p.x(), p.y());
    return GatherNeighbours(buckets, p.x(), p.y(), bx, by, reach, radius2, g.key);
  };
  // Runs of RunFits::kRun detections in detection order (one object's detections of one scan
  // side by side: often equal neighbourhoods).
  constexpr int kRun = RunFits::kRun;
  const auto run = [&](std::int64_t r) {
    RunFits fits(floor, floor_bound);
    const int j0 = static_cast<int>(r) * kRun, end = std::min(nz, j0 + kRun);
    for (int j = j0; j < end; ++j) fits.Submit(j - j0, gather(j, fits.Next()), los_b);
    fits.Finish();
    for (int j = j0; j < end; ++j) {
      det_fit_t_[j] = 0.0;
      det_fit_sd_[j] = std::numeric_limits<double>::infinity();
      DopplerFit f;
      if (!fits.Result(j - j0, &f)) continue;
      // The velocity's part along this detection's tangent (-u_y, u_x), and its variance
      // t^T (scale^2 A^-1) t.
      const double tx = -los[3 * j + 1], ty = los[3 * j];
      const double det = f.a00 * f.a11 - f.a01 * f.a01;
      const double var =
          f.scale * f.scale * (tx * tx * f.a11 - 2.0 * tx * ty * f.a01 + ty * ty * f.a00) / det;
      det_fit_t_[j] = f.vx * tx + f.vy * ty;
      det_fit_sd_[j] = std::sqrt(std::max(0.0, var));
    }
  };
  ForDynamicNoWait(t, (nz + kRun - 1) / kRun, run);  // Fill's contract: no barrier at the end
}

}  // namespace dualgrid::filter
