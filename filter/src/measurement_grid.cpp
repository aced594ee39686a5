// Step 4 of the cycle (docs/algorithm.md, paper eqs. 2-4): nearest detection per cell, detection
// buckets, the per-sensor ray free space and the detections' lines of sight (MeasurementGrid).
#include "dualgrid/filter/measurement_grid.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>

#include <hwy/highway.h>

#include "dualgrid/core/parallel.hpp"
#include "dualgrid/core/text.hpp"
#include "dualgrid/filter/fast_atan2.hpp"
#include "grid_internal.hpp"
#include "team.hpp"

namespace dualgrid::filter {

using namespace detail;

namespace {

// Columns of a detection's stamp whose squared x offsets StampBands tables at once.
constexpr int kStampColumns = 32;

// Bound on |FastAtan2 - atan2| (measured 2.04e-4 rad at the octant boundary), with margin.
constexpr double kAtanError = 5e-4;
// Half width [rad] of the directions around a view bound (ViewBound) whose cells WalkRow leaves
// to the exact test. A cell's computed bearing is FastAtan2's exact-arithmetic value at a
// direction within ~1e-15 rad of the cell's, +- 2.2e-15 rad (the roundings of fx, fy, the
// division, the polynomial and pi - r); that function's slope is 0.976 - 1.005 between its
// jumps; the bins' index (rel + half_fov) / free_angle_bin moves its bounds by < 2e-15 rad; the
// bounds' directions (Newton, rotation) are within ~1e-15 rad. Beyond 1e-11 rad (over 1,000
// times their sum) a cell's bearing is on the side of the bound its direction is on.
constexpr double kAngleMargin = 1e-11;
// Rounding of positions [m] per metre of coordinate magnitude (x0, the sensor, dx, dy), with a
// wide margin (a double's is 1.1e-16).
constexpr double kPositionMargin = 1e-12;

namespace hn = hwy::HWY_NAMESPACE;
using DD = hn::ScalableTag<double>;  // the pinned SSE4 target: two lanes, no FMA

// detail::FastAtan2 on lanes: its IEEE operations in its order, lane by lane (same bits).
hn::Vec<DD> FastAtan2V(hn::Vec<DD> y, hn::Vec<DD> x) {
  const DD d;
  const auto ax = hn::Abs(x), ay = hn::Abs(y);
  const auto mx = hn::Max(ax, ay), mn = hn::Min(ax, ay);
  const auto a = hn::Div(mn, mx), s = hn::Mul(a, a);
  auto r = hn::Add(hn::Mul(hn::Mul(hn::Sub(hn::Mul(hn::Add(hn::Mul(hn::Set(d, -0.0464964749), s),
                                                           hn::Set(d, 0.15931422)),
                                                   s),
                                           hn::Set(d, 0.327622764)),
                                   s),
                           a),
                   a);
  r = hn::IfThenElse(hn::Gt(ay, ax), hn::Sub(hn::Set(d, 0.5 * kPi), r), r);
  r = hn::IfThenElse(hn::Lt(x, hn::Zero(d)), hn::Sub(hn::Set(d, kPi), r), r);
  r = hn::IfThenElse(hn::Lt(y, hn::Zero(d)), hn::Neg(r), r);
  return hn::IfThenZeroElse(hn::Eq(mx, hn::Zero(d)), r);
}

// The a in [0, 1] with FastAtanOctant(a) = v, v in [0, FastAtanOctant(1)] (Newton from tan v,
// which is within 2.1e-4; the slope is >= 0.49: to ~1e-16 in five steps).
double InverseAtanOctant(double v) {
  double a = std::clamp(std::tan(v), 0.0, 1.0);
  for (int i = 0; i < 5; ++i) {
    const double s = a * a;
    const double slope = 1.0 + s * (-3.0 * kAtanC1 + s * (5.0 * kAtanC2 - 7.0 * kAtanC3 * s));
    a = std::clamp(a - (FastAtanOctant(a) - v) / slope, 0.0, 1.0);
  }
  return a;
}

// The unit direction (x, y) whose FastAtan2 (exact arithmetic) is t [rad], |t| < pi/2: FastAtan2
// increases with the direction, and every t within its jump at the octant bound (FastAtanOctant(1)
// to pi/2 - FastAtanOctant(1), 4.1e-4 rad) maps to that bound, pi/4.
std::array<double, 2> FastAtan2Direction(double t) {
  const double v = std::abs(t), p1 = FastAtanOctant(1.0);
  double x = 1.0, y = 1.0;
  if (v <= p1) {
    y = InverseAtanOctant(v);
  } else if (v >= 0.5 * kPi - p1) {
    x = InverseAtanOctant(std::max(0.0, 0.5 * kPi - v));
  }
  const double n = std::hypot(x, y);
  return {x / n, (t < 0.0 ? -y : y) / n};
}

// One sensor's constants along one logical row (FieldOfViewRow): cell lx's centre lies at
// dx = x0 + (lx + 0.5) r - ox, dy from the sensor; cb, sb: cos, sin of the boresight.
// bins[0, nbins): the sensor's bearing bins' ranges [m], inv_bin their inverse width [1/rad],
// run_end[b] the last bin of b's run of equal ranges; the row starts at view + row in storage,
// logical column 0 at storage column sx0 of nx.
struct RowSensor {
  double x0, r, ox, dy, cb, sb, tan_hf, half_fov, min2, max2;
  bool narrow;
  const double* bins;
  const int* run_end;
  int nbins;
  double inv_bin;
  std::int64_t row, sx0, nx;
  int ly;  // the logical row
};

// Cells per batch of ExactGeometry.
constexpr int kExactBatch = 32;

// The exact per-cell test's geometry for cells lx[0, m) (m <= kExactBatch; lx, d2, rel and in
// hold kExactBatch entries, lx set up to m rounded up to whole lanes): each cell's squared
// distance d2 [m^2], bearing rel [rad] (FastAtan2) and in = 1 when it lies within the range and
// the field of view (0 otherwise), on lanes: the scalar test's operations, same bits.
void ExactGeometry(const RowSensor& c, const int* lx, int m, double* d2, double* rel, double* in) {
  const DD d;
  const int lanes = static_cast<int>(hn::Lanes(d));
  const hn::Rebind<std::int32_t, DD> di;
  const auto x0 = hn::Set(d, c.x0), r = hn::Set(d, c.r), ox = hn::Set(d, c.ox);
  const auto half = hn::Set(d, 0.5), dydy = hn::Set(d, c.dy * c.dy);
  const auto cb = hn::Set(d, c.cb), sb = hn::Set(d, c.sb), tan_hf = hn::Set(d, c.tan_hf);
  const auto dysb = hn::Set(d, c.dy * c.sb), dycb = hn::Set(d, c.dy * c.cb);
  const auto min2 = hn::Set(d, c.min2), max2 = hn::Set(d, c.max2);
  const auto hf = hn::Set(d, c.half_fov);
  for (int i = 0; i < m; i += lanes) {  // lx, d2, rel, in: kExactBatch entries (a whole tail)
    const auto l = hn::PromoteTo(d, hn::LoadU(di, lx + i));
    const auto dx = hn::Sub(hn::Add(x0, hn::Mul(hn::Add(l, half), r)), ox);
    const auto dd = hn::Add(hn::Mul(dx, dx), dydy);
    auto ok = hn::And(hn::Not(hn::Lt(dd, min2)), hn::Not(hn::Gt(dd, max2)));
    const auto fx = hn::Add(hn::Mul(dx, cb), dysb), fy = hn::Sub(dycb, hn::Mul(dx, sb));
    if (c.narrow) {
      ok =
          hn::AndNot(hn::Or(hn::Le(fx, hn::Zero(d)), hn::Gt(hn::Abs(fy), hn::Mul(fx, tan_hf))), ok);
    }
    const auto a = FastAtan2V(fy, fx);
    ok = hn::AndNot(hn::Gt(hn::Abs(a), hf), ok);
    hn::StoreU(dd, d, d2 + i);
    hn::StoreU(a, d, rel + i);
    hn::StoreU(hn::IfThenElseZero(ok, hn::Set(d, 1.0)), d, in + i);
  }
}

// The exact per-cell test (the reference definition of the bits) of cells lx[0, m) (m <=
// kExactBatch; lx holds kExactBatch + 1 entries): their geometry on lanes (ExactGeometry), then
// the bin of each cell inside, OR-ed into `view`.
void ExactCells(const RowSensor& c, int* lx, int m, std::uint8_t* view) {
  if (m == 0) return;
  lx[m] = lx[m - 1];  // whole lanes
  double d2[kExactBatch + 1], rel[kExactBatch + 1], in[kExactBatch + 1];
  ExactGeometry(c, lx, m, d2, rel, in);
  for (int i = 0; i < m; ++i) {
    if (in[i] == 0.0) continue;
    const std::int64_t sx = c.sx0 + lx[i];
    const std::int64_t s = c.row + (sx >= c.nx ? sx - c.nx : sx);
    const int b = std::clamp(static_cast<int>((rel[i] + c.half_fov) * c.inv_bin), 0, c.nbins - 1);
    const double br = c.bins[b];
    // Free in front of the bin's closest detection, unknown behind it; a bin without any
    // detection is weakly free over the whole range.
    view[s] |= static_cast<std::uint8_t>(kObserved | (br == kInf ? kNoReturn : 0) |
                                         (br != kInf && d2[i] < br * br ? kFreeRay : 0));
  }
}

// Cells queued for the exact test (ExactCells), in batches of kExactBatch; Flush at the end.
class ExactQueue {
 public:
  ExactQueue(const RowSensor& c, std::uint8_t* view) : c_(c), view_(view) {}
  void Add(int lx) {
    lx_[n_++] = lx;
    if (n_ == kExactBatch) Flush();
  }
  void Flush() {
    ExactCells(c_, lx_, n_, view_);
    n_ = 0;
  }

 private:
  const RowSensor& c_;
  std::uint8_t* view_;
  int lx_[kExactBatch + 1];
  int n_ = 0;
};

// FastAtan2 bearing [rad] of cell lx relative to the boresight; *fx: its distance along it [m].
double RelOf(const RowSensor& c, int lx, double* fx) {
  const double dxe = c.x0 + (lx + 0.5) * c.r - c.ox;
  *fx = dxe * c.cb + c.dy * c.sb;
  return FastAtan2(c.dy * c.cb - dxe * c.sb, *fx);
}

// The dx interval [*dmin, *dmax] [m] of the row's points inside the wedge of half angle
// atan(tan_w) around the boresight (fx > 0, fx tan - fy >= 0, fx tan + fy >= 0: three linear
// conditions in dx); false when it is empty.
// With min_k > 0, false also when a condition's slope |k| is at most min_k (its bound in doubt).
bool WedgeInterval(const RowSensor& c, double tan_w, double* dmin, double* dmax,
                   double min_k = 0.0) {
  *dmin = -kInf;
  *dmax = kInf;
  const double cb = c.cb, sb = c.sb, dy = c.dy;
  for (const auto& [k, d] :
       {std::pair{cb, dy * sb}, std::pair{cb * tan_w + sb, dy * (sb * tan_w - cb)},
        std::pair{cb * tan_w - sb, dy * (sb * tan_w + cb)}}) {
    if (min_k > 0.0 && !(std::abs(k) > min_k)) return false;
    if (k > 0.0) {
      *dmin = std::max(*dmin, -d / k);
    } else if (k < 0.0) {
      *dmax = std::min(*dmax, -d / k);
    } else if (d < 0.0) {
      *dmax = -kInf;
    }
  }
  return *dmin <= *dmax;
}

// A narrow sensor's row [*lo_x, *hi_x] clipped to its wedge, two cells of margin (the exact test
// or the walk still decides every cell). False when the row misses the wedge.
bool WedgeSpan(const RowSensor& c, int* lo_x, int* hi_x) {
  const double ax = c.x0 + 0.5 * c.r - c.ox;  // dx of cell lx = ax + lx r
  const double big = 4.0 * static_cast<double>(c.nx);
  double dmin, dmax;
  if (!WedgeInterval(c, c.tan_hf, &dmin, &dmax)) return false;
  const double l0 = std::clamp(std::floor((dmin - ax) / c.r) - 2.0, -big, big);
  const double l1 = std::clamp(std::ceil((dmax - ax) / c.r) + 2.0, -big, big);
  *lo_x = std::max(*lo_x, static_cast<int>(l0));
  *hi_x = std::min(*hi_x, static_cast<int>(l1));
  return true;
}

// The cells [*in_a, *in_b] of the row that pass the range and wedge tests for certain (left
// as they are when none or in doubt): 1e-9 inside the squared range and inside the half angle
// (tan_in: tan(half_fov - 1e-9), <= 0: none), a cell of margin; far above the tests' roundings.
void CertainCells(const RowSensor& c, double tan_in, int* in_a, int* in_b) {
  const double hx2 = c.max2 * (1.0 - 1e-9) - c.dy * c.dy;
  if (!(c.dy * c.dy >= c.min2 && hx2 > 0.0 && (!c.narrow || tan_in > 0.0))) return;
  double dmin = -std::sqrt(hx2), dmax = -dmin, wmin, wmax;
  if (c.narrow) {
    if (!WedgeInterval(c, tan_in, &wmin, &wmax, 1e-9)) return;
    dmin = std::max(dmin, wmin);
    dmax = std::min(dmax, wmax);
  }
  const double ax = c.x0 + 0.5 * c.r - c.ox, big = 4.0 * static_cast<double>(c.nx);  // dx - lx r
  *in_a = static_cast<int>(std::clamp(std::ceil((dmin - ax) / c.r) + 1.0, -big, big));
  *in_b = static_cast<int>(std::clamp(std::floor((dmax - ax) / c.r) - 1.0, -big, big));
}

// Cells per window of RowWindow.
constexpr int kWindow = 128;
// RowWindow's keys beside a squared range: every cell in front of its range (any d2 < it), none.
constexpr double kFreeKey = std::numeric_limits<double>::max();
constexpr double kNoKey = -1.0;

// One sensor's bits along its row, put cell after cell from a first one: per cell the range of
// its bins (then its bearing lies within the field of view) or none (a cell the exact test
// decides, or outside the field of view). Each window of kWindow cells then gets the exact
// test's range and wedge parts per cell on lanes (its operations lane by lane, the same bits),
// and its bits OR-ed into the view where the storage row wraps or not. Flush at the end.
class RowWindow {
 public:
  // Cells [in_a, in_b] (none when in_a > in_b) pass the range and wedge tests for certain.
  RowWindow(const RowSensor& c, std::uint8_t* view, int first, int in_a, int in_b)
      : c_(c), view_(view), base_(first), in_a_(in_a), in_b_(in_b) {}
  // Cells [a, e], a the cell after the last Put's, under `key`: the square of their bins' range
  // [m^2] (kInf: no detection; kFreeKey, 0: every cell in range is in front of, behind it), or
  // kNoKey: no bits here. The certain cells take Inner, the others the window.
  void Put(int a, int e, double key) {
    if (a > e) return;
    const int ia = std::max(a, in_a_), ib = std::min(e, in_b_);
    if (ia > ib) {
      Window(a, e, key);
      return;
    }
    Window(a, ia - 1, key);
    Flush();
    Inner(ia, ib, key);
    base_ = ib + 1;
    Window(ib + 1, e, key);
  }
  // Cells [a, e], a the cell after the window's last, in the window (any cells).
  void Window(int a, int e, double key) {
    while (a <= e) {
      const int m = std::min(e, base_ + kWindow - 1);
      std::fill(key_ + (a - base_), key_ + (m - base_ + 1), key);
      n_ = m - base_ + 1;
      if (n_ == kWindow) Flush();
      a = m + 1;
    }
  }
  // Cells [a, e] of the certain ones under key: its bits, OR-ed into the view.
  void Inner(int a, int e, double key) {
    if (key < 0.0) return;  // kNoKey
    const std::uint8_t fixed = key == kInf       ? (kObserved | kNoReturn)
                               : key == kFreeKey ? (kObserved | kFreeRay)
                               : key == 0.0      ? kObserved
                                                 : 0;
    const double x0 = c_.x0, r = c_.r, ox = c_.ox, dydy = c_.dy * c_.dy;
    const int wrap = static_cast<int>(c_.nx - c_.sx0);  // first lx whose storage column wraps
    for (int part = 0; part < 2; ++part) {
      const int pa = part == 0 ? a : std::max(a, wrap);
      const int pe = part == 0 ? std::min(e, wrap - 1) : e;
      std::uint8_t* dst = view_ + c_.row + c_.sx0 - (part == 0 ? 0 : c_.nx);
      if (fixed != 0) {
        for (int lx = pa; lx <= pe; ++lx) dst[lx] |= fixed;
        continue;
      }
      for (int lx = pa; lx <= pe; ++lx) {  // in front of the range or not, per cell
        const double dx = x0 + (lx + 0.5) * r - ox;
        dst[lx] |= dx * dx + dydy < key ? (kObserved | kFreeRay) : kObserved;
      }
    }
  }
  void Flush() {
    if (n_ == 0) return;
    const DD d;
    const int lanes = static_cast<int>(hn::Lanes(d));
    const hn::Rebind<std::int32_t, DD> di;
    const hn::Rebind<std::uint8_t, DD> du8;
    const auto x0 = hn::Set(d, c_.x0), r = hn::Set(d, c_.r), ox = hn::Set(d, c_.ox);
    const auto dydy = hn::Set(d, c_.dy * c_.dy), dysb = hn::Set(d, c_.dy * c_.sb);
    const auto dycb = hn::Set(d, c_.dy * c_.cb), cb = hn::Set(d, c_.cb), sb = hn::Set(d, c_.sb);
    const auto min2 = hn::Set(d, c_.min2), max2 = hn::Set(d, c_.max2);
    const auto tan_hf = hn::Set(d, c_.tan_hf), inf = hn::Set(d, kInf);
    const auto observed = hn::Set(d, kObserved), no_return = hn::Set(d, kObserved | kNoReturn);
    const auto free_ray = hn::Set(d, kObserved | kFreeRay);
    const auto step = hn::Set(d, static_cast<double>(lanes));
    // lx + 0.5 of the lanes' cells (exact in a double)
    auto l = hn::Add(hn::Iota(d, 0.0), hn::Set(d, base_ + 0.5));
    std::uint8_t bits[kWindow + 2];
    key_[n_] = kNoKey;
    for (int i = 0; i < n_; i += lanes, l = hn::Add(l, step)) {  // key_: whole lanes
      const auto dx = hn::Sub(hn::Add(x0, hn::Mul(l, r)), ox);
      const auto d2 = hn::Add(hn::Mul(dx, dx), dydy);
      auto in = hn::And(hn::Ge(d2, min2), hn::Le(d2, max2));
      if (c_.narrow) {
        const auto fx = hn::Add(hn::Mul(dx, cb), dysb), fy = hn::Sub(dycb, hn::Mul(dx, sb));
        in =
            hn::And(in, hn::And(hn::Gt(fx, hn::Zero(d)), hn::Le(hn::Abs(fy), hn::Mul(fx, tan_hf))));
      }
      const auto key = hn::LoadU(d, key_ + i);
      in = hn::And(in, hn::Ge(key, hn::Zero(d)));  // kNoKey: no bits here
      const auto v = hn::IfThenElse(hn::Eq(key, inf), no_return,
                                    hn::IfThenElse(hn::Lt(d2, key), free_ray, observed));
      const auto b = hn::DemoteTo(di, hn::IfThenElseZero(in, v));
      hn::StoreU(hn::DemoteTo(du8, b), du8, bits + i);
    }
    const int base = base_, wrap = static_cast<int>(c_.nx - c_.sx0);  // first lx that wraps
    for (int part = 0; part < 2; ++part) {
      const int pa = part == 0 ? base : std::max(base, wrap);
      const int pe = part == 0 ? std::min(base + n_ - 1, wrap - 1) : base + n_ - 1;
      std::uint8_t* dst = view_ + c_.row + c_.sx0 - (part == 0 ? 0 : c_.nx);
      for (int lx = pa; lx <= pe; ++lx) dst[lx] |= bits[lx - base];
    }
    base_ += n_;
    n_ = 0;
  }

 private:
  const RowSensor& c_;
  std::uint8_t* view_;
  int base_, in_a_, in_b_, n_ = 0;
  // Per cell its key (Put); a whole lane beyond the window.
  double key_[kWindow + 2];
};

// Cells [a, e] of the row, each given the bits of the exact test: a segment whose cells' bins
// provably hold one range (below) is filled without per-cell bearings, any other is split in
// two; segments under four cells go to the exact test. The true bearing is monotonic along a row
// where fx > 0, and FastAtan2 is within kAtanError of it, so the cells' computed bearings lie
// within 2 kAtanError of the hull of the end points' ones and their bins (a monotonic function of
// the bearing) within the bins of that hull. If all those bins hold the same range, every cell
// gets the same bin value as in the exact test without its atan2.
void Settle(const RowSensor& c, int a0, int e0, ExactQueue& exact, RowWindow& out) {
  int stack[128][2];
  int top = 0;
  stack[top][0] = a0;
  stack[top][1] = e0;
  ++top;
  while (top > 0) {
    --top;
    const int a = stack[top][0], e = stack[top][1];
    if (e - a < 4) {
      for (int lx = a; lx <= e; ++lx) exact.Add(lx);
      out.Put(a, e, kNoKey);
      continue;
    }
    double fxa, fxe;
    const double ra = RelOf(c, a, &fxa), re = RelOf(c, e, &fxe);
    const double lo = std::min(ra, re) - 2.0 * kAtanError, hi = std::max(ra, re) + 2.0 * kAtanError;
    bool uniform = fxa > 0.0 && fxe > 0.0 && lo >= -c.half_fov && hi <= c.half_fov;
    double br = kInf;
    if (uniform) {
      const int b0 = std::clamp(static_cast<int>((lo + c.half_fov) * c.inv_bin), 0, c.nbins - 1);
      const int b1 = std::clamp(static_cast<int>((hi + c.half_fov) * c.inv_bin), 0, c.nbins - 1);
      br = c.bins[b0];
      uniform = c.run_end[b0] >= b1;
    }
    if (!uniform) {
      const int mid = a + (e - a) / 2;
      stack[top][0] = mid + 1;
      stack[top][1] = e;
      ++top;
      stack[top][0] = a;
      stack[top][1] = mid;
      ++top;
      continue;
    }
    out.Put(a, e, br * br);
  }
}

// dx [m] of cell lx of the row from the sensor: the expression of every per-cell test.
double DxOf(const RowSensor& c, int lx) { return c.x0 + (lx + 0.5) * c.r - c.ox; }

// The region of cell lx among a narrow sensor's view bounds vb[0, n) (ascending bearing): the
// number of bounds whose direction lies below the cell's, or -1 when the cell is not clearly in
// front of the sensor (fx) or its direction is within kAngleMargin of a probed bound. The side
// of a bound is the sign of the cross product of its direction and the cell's: in front of the
// sensor the two differ by less than pi.
int RegionAt(const RowSensor& c, const ViewBound* vb, int n, int lx, double pos_margin) {
  const double dx = DxOf(c, lx);
  const double fx = dx * c.cb + c.dy * c.sb, rho = std::abs(dx) + std::abs(c.dy);
  if (!(fx > kAngleMargin * rho)) return -1;
  const double tol = 2.0 * kAngleMargin * rho + pos_margin;
  int lo = 0, hi = n;
  while (lo < hi) {
    const int mid = lo + (hi - lo) / 2;
    const double side = vb[mid].gx * c.dy - vb[mid].gy * dx;
    if (std::abs(side) <= tol) return -1;
    if (side > 0.0) {
      lo = mid + 1;
    } else {
      hi = mid;
    }
  }
  return lo;
}

// RowWindow's key of region j of a narrow sensor's view bounds vb[0, n) on logical row ly: none
// outside the field of view, else that of the run after bound j - 1 on this row (ViewBound).
double RegionKey(const ViewBound* vb, int n, int j, int ly) {
  if (j <= 0 || j >= n) return kNoKey;
  const ViewBound& b = vb[j - 1];
  if (b.br_after == kInf) return kInf;
  if (ly >= b.mixed_lo && ly <= b.mixed_hi) return b.br_after * b.br_after;
  return ly >= b.free_lo && ly <= b.free_hi ? kFreeKey : 0.0;
}

// Cells [a, e] of a narrow sensor's row, each given the bits of the exact test, with per-cell
// bearings only within kAngleMargin of a view bound. FastAtan2, as a function of the direction,
// increases (with upward jumps) over the field of view, and so does the bins' index: a cell's
// bearing lies on the side of a bound's value its direction lies on, once their directions
// differ by more than kAngleMargin. Along the row the direction turns monotonically (up when dy <
// 0), so the row is walked from its first cell of known region (RegionAt; cells before it take
// the exact test) across the bounds' rays where they meet it (dx = dy cot), skipping those
// between regions of the same key on this row (RegionKey): each stretch between two crossings
// gets its key, the cells within the margin of a crossing take the exact test. vb[0, n): the
// sensor's bounds; the row's |dy| must exceed 1e-6 (max_range + r), so that the margin's image
// on the row (2 kAngleMargin rho^2 / |dy|) is linear to 1e-5.
void WalkRow(const RowSensor& c, const ViewBound* vb, int n, int a, int e, ExactQueue& exact,
             RowWindow& out) {
  const double ady = std::abs(c.dy), inv_r = 1.0 / c.r;
  const double ax = c.x0 + 0.5 * c.r - c.ox;  // dx of cell lx ~ ax + lx r
  const double pos_margin =
      kPositionMargin * (1.0 + std::abs(c.x0) + std::abs(c.ox) + ady + c.r * c.nx);
  int pos = a, j = -1;
  for (; pos <= e; ++pos) {
    j = RegionAt(c, vb, n, pos, pos_margin);
    if (j >= 0) break;
    exact.Add(pos);
    out.Put(pos, pos, kNoKey);
  }
  const int dj = c.dy < 0.0 ? 1 : -1;  // the regions' order along the row
  double key = RegionKey(vb, n, j, c.ly);
  while (pos <= e) {
    int jn = j + dj;  // the next region of another key
    double key_n = 0.0;
    while (jn >= 0 && jn <= n && (key_n = RegionKey(vb, n, jn, c.ly)) == key) jn += dj;
    const int k = dj > 0 ? jn - 1 : jn;                  // the bound before it
    if (jn < 0 || jn > n || !(vb[k].gy * c.dy > 0.0)) {  // none, or its ray misses the row
      out.Put(pos, e, key);
      break;
    }
    // The last cell before its crossing's margin and the first after it.
    const double dxc = c.dy * vb[k].cot;
    const double h = 2.0 * kAngleMargin * (dxc * dxc + c.dy * c.dy) / ady + pos_margin +
                     kPositionMargin * std::abs(dxc);
    const double lim_lo = pos - 1.0, lim_hi = e + 1.0;
    const int le = static_cast<int>(std::clamp(std::floor((dxc - h - ax) * inv_r), lim_lo, lim_hi));
    const int ln = static_cast<int>(std::clamp(std::ceil((dxc + h - ax) * inv_r), lim_lo, lim_hi));
    out.Put(pos, std::min(le, e), key);
    for (int lx = std::max(pos, le + 1); lx < ln; ++lx) exact.Add(lx);
    out.Put(std::max(pos, le + 1), ln - 1, kNoKey);
    pos = std::max(pos, ln);
    j = jn;
    key = key_n;
  }
}

// One row of a detection's stamp, n cells at consecutive storage columns: cell i at squared
// distance exx[i] + eyy [m^2] takes the detection j into d2[i], det[i] when that is within
// cutoff2 and below d2[i] (the scalar test's operations on lanes, without branches).
void StampRun(const double* exx, int n, double eyy, double cutoff2, int j, double* d2, int* det) {
  const DD d;
  const hn::Rebind<std::int32_t, DD> di;
  const int lanes = static_cast<int>(hn::Lanes(d));
  const auto vy = hn::Set(d, eyy), cut = hn::Set(d, cutoff2);
  const auto vj = hn::Set(d, static_cast<double>(j));  // indices are exact in a double
  int i = 0;
  for (; i + lanes <= n; i += lanes) {
    const auto v = hn::Add(hn::LoadU(d, exx + i), vy);
    const auto old = hn::LoadU(d, d2 + i);
    const auto take = hn::And(hn::Le(v, cut), hn::Lt(v, old));
    hn::StoreU(hn::IfThenElse(take, v, old), d, d2 + i);
    const auto old_j = hn::PromoteTo(d, hn::LoadU(di, det + i));
    hn::StoreU(hn::DemoteTo(di, hn::IfThenElse(take, vj, old_j)), di, det + i);
  }
  for (; i < n; ++i) {
    const double v = exx[i] + eyy;
    const bool take = (v <= cutoff2) & (v < d2[i]);
    d2[i] = take ? v : d2[i];
    det[i] = take ? j : det[i];
  }
}

}  // namespace

void detail::FastAtan2Lanes(const double* y, const double* x, int n, double* out) {
  const DD d;
  const int lanes = static_cast<int>(hn::Lanes(d));
  int i = 0;
  for (; i + lanes <= n; i += lanes)
    hn::StoreU(FastAtan2V(hn::LoadU(d, y + i), hn::LoadU(d, x + i)), d, out + i);
  for (; i < n; ++i) out[i] = FastAtan2(y[i], x[i]);
}

MeasurementGrid::MeasurementGrid(const FilterParams& params) : params_(params) {
  std::string error;
  if (!params_.IsValid(&error)) {
    throw std::invalid_argument("dualgrid::filter::MeasurementGrid: invalid FilterParams: " +
                                error);
  }
  with_fit_ = params_.birth_velocity == BirthVelocity::kDopplerFit ||
              params_.velocity_likelihood == VelocityLikelihood::kRadialFit;
  nx_ = params_.CellsX();
  ny_ = params_.CellsY();
  num_cells_ = static_cast<std::int64_t>(nx_) * ny_;
  const auto c = static_cast<std::size_t>(num_cells_);
  view_.assign(c, 0);
  near_det_.assign(c, -1);
  near_d2_.assign(c, kInf);
  stamp_span_.assign(static_cast<std::size_t>(ny_), {nx_, -1});
  const double cutoff = params_.cutoff_sigmas * params_.sigma_f;
  // Buckets at least cutoff + one cell wide: every detection within the cutoff of any point of a
  // cell lies in the 3 x 3 buckets around any particle of that cell (UpdateCells relies on it).
  bucket_cells_ = static_cast<int>(std::ceil(cutoff / params_.resolution)) + 1;
  bucket_inv_ = 1.0 / (bucket_cells_ * params_.resolution);
  nbx_ = (nx_ + bucket_cells_ - 1) / bucket_cells_;
  nby_ = (ny_ + bucket_cells_ - 1) / bucket_cells_;
  bucket_count_.assign(static_cast<std::size_t>(nbx_) * nby_, 0);
  bucket_start_.assign(static_cast<std::size_t>(nbx_) * nby_ + 1, 0);
}

bool MeasurementGrid::SharesGeometry(const FilterParams& p) const {
  const FilterParams& q = params_;
  const bool fit = p.birth_velocity == BirthVelocity::kDopplerFit ||
                   p.velocity_likelihood == VelocityLikelihood::kRadialFit;
  return p.resolution == q.resolution && p.CellsX() == nx_ && p.CellsY() == ny_ &&
         p.cutoff_sigmas == q.cutoff_sigmas && p.sigma_f == q.sigma_f &&
         p.free_angle_bin == q.free_angle_bin && p.free_bin_dilation == q.free_bin_dilation &&
         fit == with_fit_ &&
         (!fit || (p.doppler_fit_radius == q.doppler_fit_radius &&
                   p.doppler_fit_sigma == q.doppler_fit_sigma));
}

void MeasurementGrid::Build(const Position& centre, std::span<const Measurement> z,
                            std::span<const SensorCoverage> coverage) {
  Prepare(centre, z, coverage);
  if (OneThreadHere()) {  // no team to build (dualgrid/core/parallel.hpp)
    Fill(Team::Solo(), coverage);
  } else {
#pragma omp parallel
    Fill(Team::OfRegion(), coverage);
  }
}

void MeasurementGrid::Prepare(const Position& centre, std::span<const Measurement> z,
                              std::span<const SensorCoverage> coverage) {
  if (!(centre.cwiseAbs().maxCoeff() <= FilterParams::kMaxCentre)) {  // also NaN
    throw std::invalid_argument(
        "MeasurementGrid::Build: the grid centre must be finite with |x|, |y| <= 1e9 m, got " +
        FormatTuple({centre.x(), centre.y()}));
  }
  for (const SensorCoverage& c : coverage) {
    // half_fov <= pi: the angle bins (2 half_fov / free_angle_bin) stay bounded.
    if (!c.origin.allFinite() || !std::isfinite(c.boresight) || !(c.half_fov >= 0.0) ||
        !(c.half_fov <= kPi) || !(c.min_range >= 0.0) || !(c.max_range >= c.min_range) ||
        !std::isfinite(c.max_range)) {
      throw std::invalid_argument(
          "MeasurementGrid::Build: SensorCoverage needs a finite origin/boresight, "
          "0 <= half_fov <= pi and 0 <= min_range <= max_range < inf");
    }
  }
  // DynamicGrid's origin for this centre: the same cells, the same storage.
  const auto origin = OriginFor(centre, params_.resolution, nx_, ny_);
  origin_gx_ = origin[0];
  origin_gy_ = origin[1];
  z_.assign(z.begin(), z.end());  // capacity reused across builds
  // Every per-detection and per-sensor array at its size for this build (grow only).
  const std::size_t nz = z_.size();
  if (det_bucket_.size() < nz) {
    det_bucket_.resize(nz);
    det_stamp_.resize(nz);
    bucket_items_.resize(nz);
    det_x_.resize(nz);
    det_y_.resize(nz);
    det_fit_t_.resize(nz);
    det_fit_sd_.resize(nz);
  }
  if (det_los_.size() < 3 * nz) det_los_.resize(3 * nz);
  if (with_fit_ && det_los_b_.size() < 3 * nz) det_los_b_.resize(3 * nz);
  // Bearing bins per sensor: range of the closest detection shadowing each bin (Bins).
  const int ns = static_cast<int>(coverage.size());
  bin_offset_.assign(ns + 1, 0);  // small vectors; capacity is reused across cycles
  for (int s = 0; s < ns; ++s) {
    const int bins = std::max(
        1, static_cast<int>(std::ceil(2.0 * coverage[s].half_fov / params_.free_angle_bin)));
    bin_offset_[s + 1] = bin_offset_[s] + bins;
  }
  bin_range_.assign(bin_offset_[ns], kInf);
  bin_run_end_.resize(bin_range_.size());
  bound_offset_.resize(ns + 1);
  bound_.resize(bin_range_.size() + ns);  // at most bins + 1 per sensor
  sensor_trig_.resize(4 * static_cast<std::size_t>(ns));
  PlaceDetections();
}

void MeasurementGrid::Fill(const Team& t, std::span<const SensorCoverage> coverage) {
  // The serial parts beside the stamping (the buckets and lines of sight for the fit, the bins
  // for the field of view), each on one thread; the stamping's barrier orders them before use.
  SingleNoWait(t, [&] {
    FillBuckets();
    ComputeLinesOfSight();
  });
  SingleNoWait(t, [&] {
    Bins(coverage);
    FieldOfViewTables(coverage);
  });
  // The stamp's barrier: the buckets, lines of sight (the fit) and bins (the field of view) are
  // ready after it.
  if (t.shared) {
    ForDynamic(t, kStampBands,
               [&](std::int64_t b) { StampBands(static_cast<int>(b), static_cast<int>(b) + 1); });
  } else {
    StampBands(0, kStampBands);  // one pass over the detections
  }
  // Field of view and ray free space per cell (rows: each cell has one writer), then the fit,
  // which reads none of it: no barrier between them, nor after them. Build's region ends here;
  // DynamicGrid's cycle reads these tables only after two more of its barriers.
  ForDynamicNoWait(
      t, ny_, [&](std::int64_t ly) { FieldOfViewRow(static_cast<int>(ly), coverage); }, 2);
  if (with_fit_) FitDetectionVelocities(t);
  SingleNoWait(t, [&] { ++builds_; });
}

void MeasurementGrid::PlaceDetections() {
  const std::span<const Measurement> z = z_;
  const double r = params_.resolution;
  const double cutoff = params_.cutoff_sigmas * params_.sigma_f;
  const int rc = static_cast<int>(std::ceil(cutoff / r));
  std::fill(bucket_count_.begin(), bucket_count_.end(), 0);
  const int nz = static_cast<int>(z.size());
  for (int j = 0; j < nz; ++j) {
    det_bucket_[j] = -1;
    const Position& p = z[j].position;
    if (!p.allFinite() || !z[j].radial_velocity.allFinite()) continue;
    const double fx = std::floor(p.x() / r) - static_cast<double>(origin_gx_);
    const double fy = std::floor(p.y() / r) - static_cast<double>(origin_gy_);
    if (fx < -rc || fy < -rc || fx >= nx_ + rc || fy >= ny_ + rc) continue;
    const int lx = static_cast<int>(fx), ly = static_cast<int>(fy);
    const auto [bx, by] = BucketOf(p.x(), p.y());
    det_bucket_[j] = static_cast<std::int64_t>(by) * nbx_ + bx;
    ++bucket_count_[det_bucket_[j]];
    const int cy_lo = std::max(0, ly - rc);
    const int row_lo = static_cast<int>(Mod(origin_gy_ + cy_lo, ny_));
    det_stamp_[j] = {lx, ly, row_lo};
  }
}

void MeasurementGrid::FillBuckets() {
  const std::span<const Measurement> z = z_;
  const int nz = static_cast<int>(z.size());
  const std::int64_t nb = static_cast<std::int64_t>(nbx_) * nby_;
  std::int64_t acc = 0;  // exclusive prefix sums of the counts (integers: exact)
  for (std::int64_t b = 0; b < nb; ++b) {
    bucket_start_[b] = acc;
    acc += bucket_count_[b];
    bucket_count_[b] = 0;
  }
  bucket_start_[nb] = acc;
  for (int j = 0; j < nz; ++j) {
    if (det_bucket_[j] < 0) continue;
    const std::int64_t k = bucket_start_[det_bucket_[j]] + bucket_count_[det_bucket_[j]]++;
    bucket_items_[k] = j;
    det_x_[k] = z[j].position.x();
    det_y_[k] = z[j].position.y();
  }
}

void MeasurementGrid::StampBands(int band_lo, int band_hi) {
  const std::span<const Measurement> z = z_;
  const double r = params_.resolution;
  const double cutoff = params_.cutoff_sigmas * params_.sigma_f, cutoff2 = cutoff * cutoff;
  const int rc = static_cast<int>(std::ceil(cutoff / r));
  const int row_a = band_lo * ny_ / kStampBands, row_b = band_hi * ny_ / kStampBands;
  for (int srow = row_a; srow < row_b; ++srow) {  // the last build's stamps in these rows
    auto& [lo, hi] = stamp_span_[srow];
    const std::int64_t row = static_cast<std::int64_t>(srow) * nx_;
    if (lo <= hi) {
      std::fill(near_det_.begin() + row + lo, near_det_.begin() + row + hi + 1, -1);
      std::fill(near_d2_.begin() + row + lo, near_d2_.begin() + row + hi + 1, kInf);
    }
    lo = nx_;
    hi = -1;
  }
  const std::int64_t sx0 = Mod(origin_gx_, nx_);
  const int wrap = static_cast<int>(nx_ - sx0);  // first logical column whose storage wraps
  const int nz = static_cast<int>(z.size());
  for (int j = 0; j < nz; ++j) {
    if (det_bucket_[j] < 0) continue;
    const Position& p = z[j].position;
    const auto [lx, ly, row_lo] = det_stamp_[j];
    const int cy_lo = std::max(0, ly - rc), cy_hi = std::min(ny_ - 1, ly + rc);
    // Its storage rows row_lo .. end - 1 (mod ny): skip it unless they meet [row_a, row_b).
    const int end = row_lo + cy_hi - cy_lo + 1;
    if (!((row_lo < row_b && std::min(end, ny_) > row_a) || end - ny_ > row_a)) continue;
    // The stamp's columns in chunks of kStampColumns: their squared x offsets once per chunk, not
    // per row (a cell's update does not depend on the order of the detection's cells).
    const int cx_lo = std::max(0, lx - rc), cx_hi = std::min(nx_ - 1, lx + rc);
    for (int c0 = cx_lo; c0 <= cx_hi; c0 += kStampColumns) {
      const int c1 = std::min(cx_hi, c0 + kStampColumns - 1);
      double exx[kStampColumns];
      for (int cx = c0; cx <= c1; ++cx) {
        const double ex = (static_cast<double>(origin_gx_ + cx) + 0.5) * r - p.x();
        exx[cx - c0] = ex * ex;
      }
      for (int cy = cy_lo, srow = row_lo; cy <= cy_hi;
           ++cy, srow = srow + 1 == ny_ ? 0 : srow + 1) {
        if (srow < row_a || srow >= row_b) continue;
        const std::int64_t row = static_cast<std::int64_t>(srow) * nx_;
        const double ey = (static_cast<double>(origin_gy_ + cy) + 0.5) * r - p.y();
        const double eyy = ey * ey;
        auto& [lo, hi] = stamp_span_[srow];
        // Storage columns sx0 + cx, in at most two runs (the second from the row's wrap).
        for (int part = 0; part < 2; ++part) {
          const int pa = part == 0 ? c0 : std::max(c0, wrap);
          const int pe = part == 0 ? std::min(c1, wrap - 1) : c1;
          if (pa > pe) continue;
          const int first = static_cast<int>(sx0 + pa - (part == 0 ? 0 : nx_));
          StampRun(exx + (pa - c0), pe - pa + 1, eyy, cutoff2, j, near_d2_.data() + row + first,
                   near_det_.data() + row + first);
          lo = std::min(lo, first);
          hi = std::max(hi, first + pe - pa);
        }
      }
    }
  }
}

void MeasurementGrid::Bins(std::span<const SensorCoverage> cov) {
  const std::span<const Measurement> z = z_;
  const int nz = static_cast<int>(z.size());

  // Bearing bins per sensor (Prepare: bin_offset_, bin_range_ at kInf): range of the closest
  // detection shadowing each bin.
  const int ns = static_cast<int>(cov.size());
  for (int j = 0; j < nz; ++j) {
    const Measurement& m = z[j];
    if (!m.position.allFinite() || !m.sensor_position.allFinite()) continue;
    for (int s = 0; s < ns; ++s) {
      if ((cov[s].origin - m.sensor_position).squaredNorm() > 1e-6) continue;
      const Vector2 d = m.position - cov[s].origin;
      const double range = d.norm();
      const double rel = WrapAngle(FastAtan2(d.y(), d.x()) - cov[s].boresight);
      if (std::abs(rel) > cov[s].half_fov || range > cov[s].max_range) continue;
      const int bins = static_cast<int>(bin_offset_[s + 1] - bin_offset_[s]);
      const int b = std::clamp(static_cast<int>((rel + cov[s].half_fov) / params_.free_angle_bin),
                               0, bins - 1);
      for (int k = std::max(0, b - params_.free_bin_dilation);
           k <= std::min(bins - 1, b + params_.free_bin_dilation); ++k) {
        double& br = bin_range_[bin_offset_[s] + k];
        br = std::min(br, range);
      }
    }
  }
}

void MeasurementGrid::FieldOfViewTables(std::span<const SensorCoverage> cov) {
  const int ns = static_cast<int>(cov.size());
  // Per-sensor trigonometry once per cycle, not per row (Prepare sized the tables).
  for (int k = 0; k < ns; ++k) {
    sensor_trig_[4 * k] = std::cos(cov[k].boresight);
    sensor_trig_[4 * k + 1] = std::sin(cov[k].boresight);
    sensor_trig_[4 * k + 2] = cov[k].half_fov < 0.5 * kPi ? std::tan(cov[k].half_fov) : 0.0;
    // The wedge 1e-9 rad inside (RowWindow's certain cells), -1: none.
    const double inner = cov[k].half_fov - 1e-9;
    sensor_trig_[4 * k + 3] = inner > 0.0 && cov[k].half_fov < 0.5 * kPi ? std::tan(inner) : -1.0;
  }
  // Last bin of the run of equal ranges each bin belongs to (per sensor): O(1) uniformity test.
  for (int k = 0; k < ns; ++k) {
    const std::int64_t b_lo = bin_offset_[k], b_hi = bin_offset_[k + 1];
    for (std::int64_t b = b_hi - 1; b >= b_lo; --b) {
      bin_run_end_[b] = b + 1 < b_hi && bin_range_[b + 1] == bin_range_[b]
                            ? bin_run_end_[b + 1]
                            : static_cast<int>(b - b_lo);
    }
  }
  BoundDirections(cov);
  ViewBounds(cov);
}

void MeasurementGrid::BoundDirections(std::span<const SensorCoverage> cov) {
  const int ns = static_cast<int>(cov.size());
  bool same = static_cast<int>(bound_key_.size()) == ns;
  for (int k = 0; same && k < ns; ++k) {
    same = bound_key_[k].first == cov[k].half_fov &&
           bound_key_[k].second == bin_offset_[k + 1] - bin_offset_[k];
  }
  if (same) return;  // sensors fixed on the ego: computed once
  bound_key_.resize(ns);
  bound_dir_offset_.assign(ns + 1, 0);
  bound_dir_.clear();
  for (int k = 0; k < ns; ++k) {
    const std::int64_t bins = bin_offset_[k + 1] - bin_offset_[k];
    bound_key_[k] = {cov[k].half_fov, bins};
    if (cov[k].half_fov < 0.5 * kPi) {
      for (std::int64_t b = 0; b <= bins; ++b) {
        const double t = b == bins
                             ? cov[k].half_fov
                             : -cov[k].half_fov + static_cast<double>(b) * params_.free_angle_bin;
        bound_dir_.push_back(FastAtan2Direction(t));
      }
    }
    bound_dir_offset_[k + 1] = static_cast<std::int64_t>(bound_dir_.size());
  }
}

void MeasurementGrid::ViewBounds(std::span<const SensorCoverage> cov) {
  const int ns = static_cast<int>(cov.size());
  std::int64_t n = 0;
  for (int k = 0; k < ns; ++k) {
    bound_offset_[k] = n;
    if (bound_dir_offset_[k + 1] == bound_dir_offset_[k]) continue;  // a wide sensor
    const std::int64_t b_lo = bin_offset_[k], bins = bin_offset_[k + 1] - b_lo;
    const double cb = sensor_trig_[4 * k], sb = sensor_trig_[4 * k + 1];
    const std::array<double, 2>* dir = bound_dir_.data() + bound_dir_offset_[k];
    const auto add = [&](std::int64_t b, double br_after) {
      const double gx = dir[b][0] * cb - dir[b][1] * sb, gy = dir[b][0] * sb + dir[b][1] * cb;
      bound_[n++] = {gx, gy, gx / gy, br_after, 0, -1, 0, -1};
    };
    add(0, bin_range_[b_lo]);  // the field of view's start
    for (std::int64_t b = 1; b < bins; ++b) {
      if (bin_range_[b_lo + b] != bin_range_[b_lo + b - 1]) add(b, bin_range_[b_lo + b]);
    }
    add(bins, std::numeric_limits<double>::quiet_NaN());  // its end
    BoundRows(cov[k].origin.y(), bound_.data() + bound_offset_[k], n - bound_offset_[k]);
  }
  bound_offset_[ns] = n;
}

void MeasurementGrid::BoundRows(double oy, ViewBound* vb, std::int64_t n) const {
  const double r = params_.resolution, y0 = static_cast<double>(origin_gy_) * r;
  // Logical row (fractional) whose centre y0 + (ly + 0.5) r lies at y = oy + dy.
  const auto row_at = [&](double dy) {
    return std::clamp((oy + dy - y0) / r - 0.5, -2.0, static_cast<double>(ny_) + 1.0);
  };
  for (std::int64_t i = 0; i + 1 < n; ++i) {  // the run from bound i to bound i + 1
    const double br = vb[i].br_after;
    if (!(br < kInf)) continue;
    // The arc of radius br between the two directions (counterclockwise, < pi): its y extent,
    // with +-br where it turns through +-y (taken whenever that is in doubt).
    const double gx0 = vb[i].gx, gx1 = vb[i + 1].gx;
    double lo = br * std::min(vb[i].gy, vb[i + 1].gy), hi = br * std::max(vb[i].gy, vb[i + 1].gy);
    if (gx0 >= -1e-9 && gx1 <= 1e-9) hi = br;
    if (gx0 <= 1e-9 && gx1 >= -1e-9) lo = -br;
    // Margin [m]: the cells' directions within kAngleMargin of the run's bounds, the roundings
    // of d2 and of the rows' y (far below it).
    const double m = 1e-9 * (1.0 + br) +
                     kPositionMargin * (std::abs(oy) + std::abs(y0) + r * static_cast<double>(ny_));
    vb[i].mixed_lo = static_cast<int>(std::ceil(row_at(lo - m)));
    vb[i].mixed_hi = static_cast<int>(std::floor(row_at(hi + m)));
    // A row off the arc meets the run's sector wholly inside the circle or wholly outside: inside
    // when it crosses the pie (the sensor's y to the arc's extent).
    vb[i].free_lo = static_cast<int>(std::ceil(row_at(std::min(lo, 0.0))));
    vb[i].free_hi = static_cast<int>(std::floor(row_at(std::max(hi, 0.0))));
  }
}

void MeasurementGrid::FieldOfViewRow(int ly, std::span<const SensorCoverage> cov) {
  const int ns = static_cast<int>(cov.size());
  const double r = params_.resolution;
  const double x0 = static_cast<double>(origin_gx_) * r, y0 = static_cast<double>(origin_gy_) * r;
  const std::int64_t sx0 = Mod(origin_gx_, nx_);
  const std::int64_t row = Mod(origin_gy_ + ly, ny_) * nx_;
  const double cy = y0 + (ly + 0.5) * r;
  std::fill_n(view_.begin() + row, nx_, 0);  // whole storage row = whole logical row
  for (int k = 0; k < ns; ++k) {
    const SensorCoverage& sc = cov[k];
    const double dy = cy - sc.origin.y();
    if (std::abs(dy) > sc.max_range) continue;
    const double half_x = std::sqrt(sc.max_range * sc.max_range - dy * dy);
    const int lx_lo = std::max(0, static_cast<int>(std::floor((sc.origin.x() - half_x - x0) / r)));
    const int lx_hi =
        std::min(nx_ - 1, static_cast<int>(std::floor((sc.origin.x() + half_x - x0) / r)));
    // Sensor frame (fx along the boresight): the field-of-view test needs no atan2 when
    // half_fov < 90 deg; atan2 only runs for cells inside the field of view (for the bin).
    const double cb = sensor_trig_[4 * k], sb = sensor_trig_[4 * k + 1];
    const bool narrow = sc.half_fov < 0.5 * kPi;
    const double tan_hf = sensor_trig_[4 * k + 2];
    const double min2 = sc.min_range * sc.min_range, max2 = sc.max_range * sc.max_range;
    const RowSensor rs{x0,
                       r,
                       sc.origin.x(),
                       dy,
                       cb,
                       sb,
                       tan_hf,
                       sc.half_fov,
                       min2,
                       max2,
                       narrow,
                       bin_range_.data() + bin_offset_[k],
                       bin_run_end_.data() + bin_offset_[k],
                       static_cast<int>(bin_offset_[k + 1] - bin_offset_[k]),
                       1.0 / params_.free_angle_bin,
                       row,
                       sx0,
                       nx_,
                       ly};
    int lo_x = lx_lo, hi_x = lx_hi;
    if (narrow && !WedgeSpan(rs, &lo_x, &hi_x)) continue;
    if (lo_x > hi_x) continue;
    int in_a = 1, in_b = 0;
    CertainCells(rs, sensor_trig_[4 * k + 3], &in_a, &in_b);
    ExactQueue exact(rs, view_.data());
    RowWindow out(rs, view_.data(), lo_x, in_a, in_b);
    if (narrow && std::abs(dy) > 1e-6 * (sc.max_range + r)) {  // WalkRow's condition
      const std::int64_t b0 = bound_offset_[k];
      WalkRow(rs, bound_.data() + b0, static_cast<int>(bound_offset_[k + 1] - b0), lo_x, hi_x,
              exact, out);
    } else {  // a wide sensor, or a row (almost) through a narrow one
      Settle(rs, lo_x, hi_x, exact, out);
    }
    out.Flush();
    exact.Flush();
  }
}

void MeasurementGrid::ComputeLinesOfSight() {
  const int nz = static_cast<int>(z_.size());  // det_los_: Prepare sized it
  for (int j = 0; j < nz; ++j) {
    Vector2 u = z_[j].position - z_[j].sensor_position;
    const double n = u.norm();
    u = n > 0.0 ? Vector2(u / n) : Vector2(1.0, 0.0);
    det_los_[3 * j] = u.x();
    det_los_[3 * j + 1] = u.y();
    det_los_[3 * j + 2] = z_[j].radial_velocity.dot(u);
  }
  if (!with_fit_) return;
  const std::int64_t nb = static_cast<std::int64_t>(nbx_) * nby_;
  for (std::int64_t k = 0; k < bucket_start_[nb]; ++k) {  // FillBuckets ran before
    const int j = bucket_items_[k];
    std::copy_n(det_los_.begin() + 3 * j, 3, det_los_b_.begin() + 3 * k);
  }
}

}  // namespace dualgrid::filter
