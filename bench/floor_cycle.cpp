// FloorCycle (floor_cycle.hpp): the least work of a paper-size dual-weight cycle in float on
// Highway lanes, one parallel region per cycle. Constants: FilterParams' defaults.
#include "floor_cycle.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <ctime>
#include <utility>

#include <omp.h>

#include <hwy/contrib/math/math-inl.h>
#include <hwy/highway.h>

#include "dualgrid/filter/particles.hpp"
#include "dualgrid/filter/simd_normals.hpp"

namespace dualgrid::bench {

namespace hn = hwy::HWY_NAMESPACE;

// DUALGRID_FLOOR_ANY_TARGET: a build of this file for another target (docs/performance.md's AVX2
// figure: the floor on wider lanes); the filter itself stays pinned.
#if HWY_ARCH_X86 && !defined(DUALGRID_FLOOR_ANY_TARGET)
static_assert(HWY_TARGET == HWY_SSE4, "the floor is measured on the filter's pinned SSE4 target");
#endif

namespace {

using DF = hn::ScalableTag<float>;
using DI = hn::RebindToSigned<DF>;
using VF = hn::Vec<DF>;
using VI = hn::Vec<DI>;

constexpr std::int64_t kBlock = 256;       // particles per prediction block
constexpr std::int64_t kCellChunk = 1024;  // cells per chunk of the cell pass
constexpr std::int64_t kSumBlock = 1024;   // particles per block of the resampling's scan
constexpr std::uint8_t kObserved = 1, kFreeRay = 2, kNoReturn = 4;
// FilterParams' defaults.
constexpr float kSigmaF = 0.6f, kCutoff = 3.0f * kSigmaF, kSigmaV = 1.0f, kKeep = 0.95f;
constexpr float kPersistence = 0.99f, kStaticPersistence = 0.98f, kFreeDecay = 0.9f;
constexpr float kFreeMass = 0.7f, kFreeMassNoReturn = 0.3f, kOccupiedMass = 0.9f;
constexpr float kBirthProbability = 0.1f, kSlow2 = 1.0f, kBin = 0.0174533f;
constexpr float kSigmaPos = 0.3f, kSigmaVel = 1.5f, kMaxTangential = 40.0f;

// atan2 on lanes (|error| ~2e-4 rad, as the filter's FastAtan2).
inline VF Atan2(VF y, VF x) {
  const DF df;
  const VF ax = hn::Abs(x), ay = hn::Abs(y);
  const VF mx = hn::Max(ax, ay), mn = hn::Min(ax, ay);
  const VF a = hn::Div(mn, hn::Max(mx, hn::Set(df, 1e-30f))), s = hn::Mul(a, a);
  VF r = hn::Add(hn::Mul(hn::Set(df, -0.0464964749f), s), hn::Set(df, 0.15931422f));
  r = hn::Add(hn::Mul(r, s), hn::Set(df, -0.327622764f));
  r = hn::Add(hn::Mul(hn::Mul(r, s), a), a);
  r = hn::IfThenElse(hn::Gt(ay, ax), hn::Sub(hn::Set(df, 1.5707963f), r), r);
  r = hn::IfThenElse(hn::Lt(x, hn::Zero(df)), hn::Sub(hn::Set(df, 3.1415927f), r), r);
  return hn::IfThenElse(hn::Lt(y, hn::Zero(df)), hn::Neg(r), r);
}

// The first `valid` lanes of v to p.
inline void Put(VF v, float* p, std::size_t valid) {
  const DF df;
  if (valid == hn::Lanes(df)) {
    hn::StoreU(v, df, p);
    return;
  }
  alignas(16) float out[HWY_MAX_BYTES / 4];
  hn::Store(v, df, out);
  for (std::size_t k = 0; k < valid; ++k) p[k] = out[k];
}

// This thread's CPU time [s].
inline void ThreadCpu(double* t) {
  timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  *t = static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

inline double LaneSum(VF v) {
  const DF df;
  alignas(64) float l[HWY_MAX_BYTES / sizeof(float)];
  hn::Store(v, df, l);
  double s = 0.0;
  for (std::size_t k = 0; k < hn::Lanes(df); ++k) s += l[k];
  return s;
}

}  // namespace

void FloorParticles::resize(std::size_t n) {
  for (auto* v : {&x, &y, &vx, &vy, &weight, &w_position, &w_velocity}) v->resize(n + 16);
}

FloorCycle::FloorCycle(int particles, int births, int nx, int ny, double resolution,
                       std::uint64_t seed)
    : n_(particles),
      nb_(births),
      nx_(nx),
      ny_(ny),
      cells_(static_cast<std::int64_t>(nx) * ny),
      r_(static_cast<float>(resolution)),
      seed_(seed) {
  p_.resize(n_);
  s_.resize(n_ + nb_);
  cell_of_.resize(n_ + 16);
  start_.resize(cells_ + 20);  // + lanes: the quiet-cell pass reads whole vectors
  for (auto* v : {&free_, &static_, &dynamic_, &born_}) v->assign(cells_ + 16, 0.0f);
  view_.assign(cells_ + 16, 0);
  near_.assign(cells_ + 16, -1);
  near_d2_.assign(cells_ + 16, 0.0f);
  born_list_.resize(cells_);
  const std::int64_t chunks = (cells_ + kCellChunk - 1) / kCellChunk;
  born_n_.assign(chunks, 0);
  chunk_born_.assign(chunks + 1, 0.0);
  block_w_.assign((n_ + nb_) / kSumBlock + 2, 0.0);
  block_total_.assign((cells_ + 1) / kCellChunk + 2, 0);
  bucket_cells_ = static_cast<int>(std::ceil(kCutoff / r_)) + 1;
  nbx_ = (nx_ + bucket_cells_ - 1) / bucket_cells_;
  nby_ = (ny_ + bucket_cells_ - 1) / bucket_cells_;
  bucket_start_.assign(static_cast<std::size_t>(nbx_) * nby_ + 1, 0);
  // Particles spread over the grid, moving along x.
  for (int i = 0; i < n_; ++i) {
    p_.x[i] = std::fmod(i * 0.6180339f * nx_ * r_, nx_ * r_);
    p_.y[i] = std::fmod(i * 0.4142136f * ny_ * r_, ny_ * r_);
    p_.vx[i] = 25.0f + static_cast<float>(i % 13);
    p_.vy[i] = 0.0f;
    p_.weight[i] = p_.w_position[i] = p_.w_velocity[i] = 1.0f / n_;
  }
}

// Detections to grid-local float, bucket order; sensors and their bearing bins.
void FloorCycle::Inputs(const Position& centre, std::span<const filter::Measurement> z,
                        std::span<const filter::SensorCoverage> coverage) {
  const std::int64_t gx = static_cast<std::int64_t>(std::floor(centre.x() / r_)) - nx_ / 2;
  const std::int64_t gy = static_cast<std::int64_t>(std::floor(centre.y() / r_)) - ny_ / 2;
  shift_x_ = started_ ? static_cast<int>(gx - gx_) : 0;
  shift_y_ = started_ ? static_cast<int>(gy - gy_) : 0;
  gx_ = gx;
  gy_ = gy;
  started_ = true;
  const double x0 = static_cast<double>(gx) * r_, y0 = static_cast<double>(gy) * r_;
  sensors_.clear();
  int bins = 0;
  for (const filter::SensorCoverage& c : coverage) {
    Sensor s{static_cast<float>(c.origin.x() - x0),
             static_cast<float>(c.origin.y() - y0),
             static_cast<float>(std::cos(c.boresight)),
             static_cast<float>(std::sin(c.boresight)),
             static_cast<float>(std::tan(c.half_fov)),
             static_cast<float>(c.half_fov),
             static_cast<float>(c.min_range * c.min_range),
             static_cast<float>(c.max_range * c.max_range),
             bins,
             std::max(1, static_cast<int>(std::ceil(2.0 * c.half_fov / kBin)))};
    bins += s.bins;
    sensors_.push_back(s);
  }
  bin_range_.assign(bins, 1e30f);
  const int nz = static_cast<int>(z.size());
  u0_.resize(nz + 1);
  u1_.resize(nz + 1);
  u2_.resize(nz + 1);
  bucket_of_.resize(nz);
  det_.resize(nz);
  std::fill(bucket_start_.begin(), bucket_start_.end(), 0);
  const float inv_b = 1.0f / (bucket_cells_ * r_);
  for (int j = 0; j < nz; ++j) {
    const float x = static_cast<float>(z[j].position.x() - x0);
    const float y = static_cast<float>(z[j].position.y() - y0);
    const Vector2 los = (z[j].position - z[j].sensor_position).normalized();
    u0_[j] = static_cast<float>(los.x());
    u1_[j] = static_cast<float>(los.y());
    u2_[j] = static_cast<float>(z[j].radial_velocity.dot(los));
    const int bx = std::clamp(static_cast<int>(std::floor(x * inv_b)), 0, nbx_ - 1);
    const int by = std::clamp(static_cast<int>(std::floor(y * inv_b)), 0, nby_ - 1);
    bucket_of_[j] = by * nbx_ + bx;
    ++bucket_start_[bucket_of_[j] + 1];
    for (std::size_t k = 0; k < sensors_.size(); ++k) {  // the bins this detection shadows
      if ((coverage[k].origin - z[j].sensor_position).squaredNorm() > 1e-6) continue;
      const Sensor& s = sensors_[k];
      const float dx = x - s.ox, dy = y - s.oy;
      const float fx = dx * s.cb + dy * s.sb, fy = dy * s.cb - dx * s.sb;
      const float rel = std::atan2(fy, fx);
      if (std::abs(rel) > s.half_fov) continue;
      const int b = std::clamp(static_cast<int>((rel + s.half_fov) / kBin), 0, s.bins - 1);
      const float range = std::sqrt(dx * dx + dy * dy);
      for (int q = std::max(0, b - 1); q <= std::min(s.bins - 1, b + 1); ++q)
        bin_range_[s.bin0 + q] = std::min(bin_range_[s.bin0 + q], range);
    }
  }
  const int nbk = nbx_ * nby_;
  for (int b = 0; b < nbk; ++b) bucket_start_[b + 1] += bucket_start_[b];
  std::vector<std::int32_t> fill(bucket_start_.begin(), bucket_start_.end() - 1);
  for (int j = 0; j < nz; ++j) {
    const int k = fill[bucket_of_[j]]++;
    det_[k] = {static_cast<float>(z[j].position.x() - x0),
               static_cast<float>(z[j].position.y() - y0), j};
  }
}

// Rows [y_lo, y_hi): nearest detection per cell (stamped detection by detection, ties to the
// lower item) and the field of view's bits on lanes (bearing per cell through Atan2).
void FloorCycle::MeasurementRows(int y_lo, int y_hi) {
  const std::int64_t c_lo = static_cast<std::int64_t>(y_lo) * nx_,
                     c_hi = static_cast<std::int64_t>(y_hi) * nx_;
  std::fill(near_.begin() + c_lo, near_.begin() + c_hi, -1);
  std::fill(view_.begin() + c_lo, view_.begin() + c_hi, 0);
  const int rc = static_cast<int>(std::ceil(kCutoff / r_));
  const float cut2 = kCutoff * kCutoff;
  for (std::size_t k = 0; k < det_.size(); ++k) {
    const Det& d = det_[k];
    const int lx = static_cast<int>(std::floor(d.x / r_)),
              ly = static_cast<int>(std::floor(d.y / r_));
    for (int cy = std::max(y_lo, ly - rc); cy <= std::min(y_hi - 1, ly + rc); ++cy) {
      const float ey = (cy + 0.5f) * r_ - d.y;
      for (int cx = std::max(0, lx - rc); cx <= std::min(nx_ - 1, lx + rc); ++cx) {
        const float ex = (cx + 0.5f) * r_ - d.x, d2 = ex * ex + ey * ey;
        const std::int64_t c = static_cast<std::int64_t>(cy) * nx_ + cx;
        const bool better = d2 <= cut2 && (near_[c] < 0 || d2 < near_d2_[c] ||
                                           (d2 == near_d2_[c] && d.item < near_[c]));
        near_[c] = better ? d.item : near_[c];
        near_d2_[c] = better ? d2 : near_d2_[c];
      }
    }
  }
  ViewRows(y_lo, y_hi);
}

// Rows [y_lo, y_hi): the field of view's bits per cell on lanes (bearing per cell through Atan2,
// each row clipped to each sensor's range circle and wedge).
void FloorCycle::ViewRows(int y_lo, int y_hi) {
  const DF df;
  const DI di;
  const std::int64_t lanes = static_cast<std::int64_t>(hn::Lanes(df));
  for (const Sensor& s : sensors_) {
    const VF cb = hn::Set(df, s.cb), sb = hn::Set(df, s.sb), half = hn::Set(df, s.half_fov);
    const VF min2 = hn::Set(df, s.min2), max2 = hn::Set(df, s.max2), tan_hf = hn::Set(df, s.tan_hf);
    const VF inv_bin = hn::Set(df, 1.0f / kBin);
    const VI last = hn::Set(di, s.bins - 1);
    const hn::Rebind<std::uint8_t, DI> d8;
    const float max_r = std::sqrt(s.max2);
    for (int cy = y_lo; cy < y_hi; ++cy) {
      const float dyf = (cy + 0.5f) * r_ - s.oy;
      if (std::abs(dyf) > max_r) continue;
      const float half_x = std::sqrt(s.max2 - dyf * dyf);
      // The row clipped to the range circle and to the wedge (three half-planes in dx, one cell
      // of margin; the per-cell test below decides every cell).
      float dmin = -half_x, dmax = half_x;
      for (const auto& [c, d] :
           {std::pair{s.cb, dyf * s.sb},
            std::pair{s.cb * s.tan_hf + s.sb, dyf * (s.sb * s.tan_hf - s.cb)},
            std::pair{s.cb * s.tan_hf - s.sb, dyf * (s.sb * s.tan_hf + s.cb)}}) {
        if (c > 0.0f) dmin = std::max(dmin, -d / c);
        if (c < 0.0f) dmax = std::min(dmax, -d / c);
        if (c == 0.0f && d < 0.0f) dmax = -1e30f;
      }
      if (dmin > dmax) continue;
      const int x_lo = std::max(0, static_cast<int>(std::floor((s.ox + dmin) / r_)) - 1);
      const int x_hi = std::min(nx_, static_cast<int>(std::ceil((s.ox + dmax) / r_)) + 1);
      const VF dy = hn::Set(df, dyf);
      std::uint8_t* row = view_.data() + static_cast<std::int64_t>(cy) * nx_;
      for (int cx = x_lo; cx < x_hi; cx += static_cast<int>(lanes)) {
        const VF dx =
            hn::Sub(hn::Mul(hn::Add(hn::ConvertTo(df, hn::Iota(di, cx)), hn::Set(df, 0.5f)),
                            hn::Set(df, r_)),
                    hn::Set(df, s.ox));
        const VF d2 = hn::Add(hn::Mul(dx, dx), hn::Mul(dy, dy));
        const VF fx = hn::Add(hn::Mul(dx, cb), hn::Mul(dy, sb));
        const VF fy = hn::Sub(hn::Mul(dy, cb), hn::Mul(dx, sb));
        const auto in =
            hn::And(hn::And(hn::Ge(d2, min2), hn::Le(d2, max2)),
                    hn::And(hn::Gt(fx, hn::Zero(df)), hn::Le(hn::Abs(fy), hn::Mul(fx, tan_hf))));
        const VI b =
            hn::Min(hn::Max(hn::ConvertTo(di, hn::Mul(hn::Add(Atan2(fy, fx), half), inv_bin)),
                            hn::Zero(di)),
                    last);
        const VF br = hn::GatherIndex(df, bin_range_.data() + s.bin0, b);
        const VI none = hn::VecFromMask(di, hn::RebindMask(di, hn::Ge(br, hn::Set(df, 1e29f))));
        const VI front = hn::VecFromMask(di, hn::RebindMask(di, hn::Lt(hn::Mul(br, br), d2)));
        VI bits = hn::Or(hn::Set(di, kObserved),
                         hn::Or(hn::And(none, hn::Set(di, kNoReturn)),
                                hn::AndNot(hn::Or(none, front), hn::Set(di, kFreeRay))));
        bits = hn::IfThenElseZero(hn::RebindMask(di, in), bits);
        const auto bytes = hn::DemoteTo(d8, bits);
        if (cx + lanes <= x_hi) {  // whole vector inside the row's segment
          hn::StoreU(hn::Or(hn::LoadU(d8, row + cx), bytes), d8, row + cx);
        } else {
          alignas(16) std::uint8_t out[HWY_MAX_BYTES / 4];
          hn::Store(bytes, d8, out);
          for (int k = 0; cx + k < x_hi; ++k) row[cx + k] |= out[k];
        }
      }
    }
  }
}

// Thread t of `threads`: its chunk of particles predicted (Philox normals on lanes), re-origined,
// binned; its histogram counted.
void FloorCycle::Predict(int t, int threads, float dt) {
  const DF df;
  const DI di;
  const std::int64_t lanes = static_cast<std::int64_t>(hn::Lanes(df));
  const std::int64_t lo = static_cast<std::int64_t>(n_) * t / threads,
                     hi = static_cast<std::int64_t>(n_) * (t + 1) / threads;
  std::int32_t* h = hist_.data() + t * (cells_ + 1);
  std::fill_n(h, cells_ + 1, 0);
  const VF sp = hn::Set(df, kSigmaPos * std::sqrt(dt)), sv = hn::Set(df, kSigmaVel * std::sqrt(dt));
  const VF vdt = hn::Set(df, dt), keep = hn::Set(df, kPersistence), inv_r = hn::Set(df, 1.0f / r_);
  const VF shx = hn::Set(df, shift_x_ * r_), shy = hn::Set(df, shift_y_ * r_);
  const VF fnx = hn::Set(df, static_cast<float>(nx_)), fny = hn::Set(df, static_cast<float>(ny_));
  const VI nx = hn::Set(di, nx_), off = hn::Set(di, static_cast<std::int32_t>(cells_));
  alignas(64) float g[4][kBlock];
  for (std::int64_t b0 = lo; b0 < hi; b0 += kBlock) {
    const std::int64_t m = std::min(kBlock, hi - b0);
    filter::detail::PredictionNormalLanes(seed_, step_, static_cast<std::uint32_t>(b0), m, g[0],
                                          g[1], g[2], g[3]);
    for (std::int64_t k = 0; k < m; k += lanes) {  // arrays padded by 16: whole vectors
      const std::int64_t i = b0 + k;
      const VF vx = hn::LoadU(df, &p_.vx[i]), vy = hn::LoadU(df, &p_.vy[i]);
      const VF x = hn::Add(hn::Sub(hn::LoadU(df, &p_.x[i]), shx),
                           hn::Add(hn::Mul(vx, vdt), hn::Mul(sp, hn::Load(df, g[0] + k))));
      const VF y = hn::Add(hn::Sub(hn::LoadU(df, &p_.y[i]), shy),
                           hn::Add(hn::Mul(vy, vdt), hn::Mul(sp, hn::Load(df, g[1] + k))));
      hn::StoreU(x, df, &p_.x[i]);
      hn::StoreU(y, df, &p_.y[i]);
      hn::StoreU(hn::Add(vx, hn::Mul(sv, hn::Load(df, g[2] + k))), df, &p_.vx[i]);
      hn::StoreU(hn::Add(vy, hn::Mul(sv, hn::Load(df, g[3] + k))), df, &p_.vy[i]);
      for (auto* w : {&p_.weight, &p_.w_position, &p_.w_velocity})
        hn::StoreU(hn::Mul(hn::LoadU(df, &(*w)[i]), keep), df, &(*w)[i]);
      const VF fx = hn::Floor(hn::Mul(x, inv_r)), fy = hn::Floor(hn::Mul(y, inv_r));
      const auto inside = hn::And(hn::And(hn::Ge(fx, hn::Zero(df)), hn::Ge(fy, hn::Zero(df))),
                                  hn::And(hn::Lt(fx, fnx), hn::Lt(fy, fny)));
      const VI c = hn::Add(hn::Mul(hn::ConvertTo(di, fy), nx), hn::ConvertTo(di, fx));
      hn::StoreU(hn::IfThenElse(hn::RebindMask(di, inside), c, off), di, &cell_of_[i]);
    }
    for (std::int64_t i = b0; i < b0 + m; ++i) ++h[cell_of_[i]];
  }
}

// The quiet cells of [c_lo, c_hi) (no particle, no detection) on lanes: the free/static update
// with no dynamic or new-born mass; the other cells keep their values for UpdateCell.
void FloorCycle::QuietCells(std::int64_t c_lo, std::int64_t c_hi) {
  const DF df;
  const DI di;
  const std::int64_t lanes = static_cast<std::int64_t>(hn::Lanes(df));
  const hn::Rebind<std::uint8_t, DI> d8;
  for (std::int64_t c = c_lo; c < c_hi; c += lanes) {  // layers padded by 16: whole vectors
    const VI cnt = hn::Sub(hn::LoadU(di, &start_[c + 1]), hn::LoadU(di, &start_[c]));
    const auto quiet = hn::RebindMask(
        df, hn::And(hn::Eq(cnt, hn::Zero(di)), hn::Lt(hn::LoadU(di, &near_[c]), hn::Zero(di))));
    const VI v = hn::PromoteTo(di, hn::LoadU(d8, &view_[c]));
    const auto obs = hn::RebindMask(df, hn::Ne(hn::And(v, hn::Set(di, kObserved)), hn::Zero(di)));
    const auto ray = hn::RebindMask(df, hn::Ne(hn::And(v, hn::Set(di, kFreeRay)), hn::Zero(di)));
    const VF zf = hn::IfThenElseZero(
        obs, hn::IfThenElse(ray, hn::Set(df, kFreeMass), hn::Set(df, kFreeMassNoReturn)));
    const VF one = hn::Set(df, 1.0f), st = hn::LoadU(df, &static_[c]),
             fr = hn::LoadU(df, &free_[c]);
    const VF s_pred = hn::Min(hn::Mul(st, hn::Set(df, kStaticPersistence)), one);
    const VF f_pred =
        hn::Max(hn::Zero(df), hn::Min(hn::Mul(fr, hn::Set(df, kFreeDecay)), hn::Sub(one, s_pred)));
    const VF u_pred = hn::Max(hn::Zero(df), hn::Sub(hn::Sub(one, s_pred), f_pred));
    const VF norm = hn::Div(one, hn::Sub(one, hn::Mul(s_pred, zf)));
    hn::StoreU(hn::IfThenElse(quiet, hn::Mul(hn::Add(f_pred, hn::Mul(u_pred, zf)), norm), fr), df,
               &free_[c]);
    hn::StoreU(hn::IfThenElse(quiet, hn::Mul(hn::Mul(s_pred, hn::Sub(one, zf)), norm), st), df,
               &static_[c]);
    hn::StoreU(hn::IfThenElseZero(hn::Not(quiet), hn::LoadU(df, &dynamic_[c])), df, &dynamic_[c]);
    hn::StoreU(hn::IfThenElseZero(hn::Not(quiet), hn::LoadU(df, &born_[c])), df, &born_[c]);
  }
}

// The particles [lo, hi) of one cell: the nearest of the 3 x 3 buckets' detections, eqs. (7),
// (8) with two exps on lanes, the weights unnormalised, the per-cell sums.
FloorCycle::CellSums FloorCycle::WeighCell(std::int32_t lo, std::int32_t hi, float cap,
                                           bool observed) {
  const DF df;
  const DI di;
  const std::int64_t lanes = static_cast<std::int64_t>(hn::Lanes(df));
  const float inv_b = 1.0f / (bucket_cells_ * r_);
  // The particles: nearest candidate detection of the 3 x 3 buckets, eqs. (7), (8), sums.
  std::int32_t cand[3][2] = {{0, 0}, {0, 0}, {0, 0}};
  if (hi > lo) {
    const int bx = std::clamp(static_cast<int>(std::floor(s_.x[lo] * inv_b)), 0, nbx_ - 1);
    const int by = std::clamp(static_cast<int>(std::floor(s_.y[lo] * inv_b)), 0, nby_ - 1);
    const int x0 = std::max(0, bx - 1), x1 = std::min(nbx_ - 1, bx + 1);
    for (int yy = std::max(0, by - 1), q = 0; yy <= std::min(nby_ - 1, by + 1); ++yy, ++q) {
      cand[q][0] = bucket_start_[yy * nbx_ + x0];
      cand[q][1] = bucket_start_[yy * nbx_ + x1 + 1];
    }
  }
  const VF z = hn::Zero(df);
  VF acc_slow = z, acc_fast = z, acc_pos = z, acc_vel = z, acc_dyn = z;
  const VF keep = hn::Set(df, kKeep), one = hn::Set(df, 1.0f), vcap = hn::Set(df, cap);
  for (std::int32_t i = lo; i < hi; i += static_cast<std::int32_t>(lanes)) {
    const std::size_t valid = static_cast<std::size_t>(std::min<std::int64_t>(lanes, hi - i));
    const auto live = hn::FirstN(df, valid);
    const VF x = hn::LoadU(df, &s_.x[i]), y = hn::LoadU(df, &s_.y[i]);
    const VF vx = hn::LoadU(df, &s_.vx[i]), vy = hn::LoadU(df, &s_.vy[i]);
    const VF m = hn::Mul(hn::LoadU(df, &s_.weight[i]), vcap);
    const auto slow =
        hn::And(live, hn::Lt(hn::Add(hn::Mul(vx, vx), hn::Mul(vy, vy)), hn::Set(df, kSlow2)));
    const auto fast = hn::AndNot(slow, live);
    VF d2 = hn::Set(df, kCutoff * kCutoff);
    VI jn = hn::Set(di, -1);
    for (const auto& range : cand) {
      for (std::int32_t k = range[0]; k < range[1]; ++k) {
        const VF ex = hn::Sub(hn::Set(df, det_[k].x), x), ey = hn::Sub(hn::Set(df, det_[k].y), y);
        const VF e2 = hn::Add(hn::Mul(ex, ex), hn::Mul(ey, ey));
        const auto better = hn::Lt(e2, d2);
        d2 = hn::IfThenElse(better, e2, d2);
        jn = hn::IfThenElse(hn::RebindMask(di, better), hn::Set(di, det_[k].item), jn);
      }
    }
    const auto has = hn::RebindMask(df, hn::Gt(jn, hn::Set(di, -1)));
    const VI jc = hn::Max(jn, hn::Zero(di));
    const VF e = hn::Sub(hn::Add(hn::Mul(vx, hn::GatherIndex(df, u0_.data(), jc)),
                                 hn::Mul(vy, hn::GatherIndex(df, u1_.data(), jc))),
                         hn::GatherIndex(df, u2_.data(), jc));
    const VF fd =
        hn::IfThenElseZero(has, hn::Exp(df, hn::Mul(d2, hn::Set(df, -0.5f / (kSigmaF * kSigmaF)))));
    const VF fv = hn::IfThenElseZero(
        has, hn::Exp(df, hn::Mul(hn::Mul(e, e), hn::Set(df, -0.5f / (kSigmaV * kSigmaV)))));
    const auto scored = observed ? hn::FirstN(df, lanes) : has;
    const VF lp = hn::IfThenElse(scored, hn::Mul(fd, keep), keep);
    const VF lv =
        hn::IfThenElse(scored, hn::Add(hn::Mul(fd, fv), hn::Mul(hn::Sub(one, fd), keep)), keep);
    const VF wp = hn::IfThenElseZero(fast, hn::Mul(lp, hn::LoadU(df, &s_.w_position[i])));
    const VF wv = hn::IfThenElseZero(fast, hn::Mul(lv, hn::LoadU(df, &s_.w_velocity[i])));
    const VF mf = hn::IfThenElseZero(fast, m);
    Put(mf, &s_.weight[i], valid);  // no write past the cell
    Put(wp, &s_.w_position[i], valid);
    Put(wv, &s_.w_velocity[i], valid);
    acc_slow = hn::Add(acc_slow, hn::IfThenElseZero(slow, m));
    acc_fast = hn::Add(acc_fast, mf);
    acc_pos = hn::Add(acc_pos, wp);
    acc_vel = hn::Add(acc_vel, wv);
    acc_dyn = hn::Add(acc_dyn, hn::Mul(mf, hn::Max(lp, lv)));
  }
  return {LaneSum(acc_slow), LaneSum(acc_fast), LaneSum(acc_pos), LaneSum(acc_vel),
          LaneSum(acc_dyn)};
}

// Eqs. (10-12) for the particles [lo, hi) on lanes: both weights to the cell's rho_p, the
// resampling weight their maximum scaled to rho_p.
void FloorCycle::NormaliseCell(std::int32_t lo, std::int32_t hi, double rho_p, double sum_pos,
                               double sum_vel) {
  const DF df;
  const std::int64_t lanes = static_cast<std::int64_t>(hn::Lanes(df));
  const VF z = hn::Zero(df);
  const VF kp = hn::Set(df, static_cast<float>(sum_pos > 0.0 ? rho_p / sum_pos : 0.0));
  const VF kv = hn::Set(df, static_cast<float>(sum_vel > 0.0 ? rho_p / sum_vel : 0.0));
  VF sum = z;
  for (std::int32_t i = lo; i < hi; i += static_cast<std::int32_t>(lanes)) {
    const std::size_t valid = static_cast<std::size_t>(std::min<std::int64_t>(lanes, hi - i));
    const VF np = hn::Mul(hn::LoadU(df, &s_.w_position[i]), kp);
    const VF nv = hn::Mul(hn::LoadU(df, &s_.w_velocity[i]), kv);
    const VF nw = hn::IfThenElseZero(hn::FirstN(df, valid), hn::Max(np, nv));
    Put(nw, &s_.weight[i], valid);
    Put(np, &s_.w_position[i], valid);
    Put(nv, &s_.w_velocity[i], valid);
    sum = hn::Add(sum, nw);
  }
  const double sum_res = LaneSum(sum);
  const float k = sum_res > 0.0 ? static_cast<float>(rho_p / sum_res) : 0.0f;
  for (std::int32_t i = lo; i < hi; ++i) s_.weight[i] *= k;
}

// One cell with particles or a detection: predicted masses, the measurement (eqs. 2-4), the
// Dempster update, the weights (WeighCell), the joint normalisation (eqs. 9-12), the weights'
// normalisation. Returns the cell's new-born mass.
double FloorCycle::UpdateCell(std::int64_t c) {
  const std::int32_t lo = start_[c], hi = start_[c + 1], j = near_[c];
  float d_pred = 0.0f;
  for (std::int32_t i = lo; i < hi; ++i) d_pred += s_.weight[i];
  const float cap = d_pred > 1.0f ? 1.0f / d_pred : 1.0f;
  d_pred *= cap;
  const float s_pred = std::min(kStaticPersistence * static_[c], 1.0f - d_pred);
  const float f_pred = std::max(0.0f, std::min(kFreeDecay * free_[c], 1.0f - d_pred - s_pred));
  const float o_pred = d_pred + s_pred, u_pred = std::max(0.0f, 1.0f - o_pred - f_pred);
  const float occ = j >= 0 ? std::exp(-near_d2_[c] * (0.5f / (kSigmaF * kSigmaF))) : 0.0f;
  const bool observed = (view_[c] & kObserved) != 0;
  const float z_occ = kOccupiedMass * occ;
  const float z_free =
      observed ? ((view_[c] & kFreeRay) ? kFreeMass : kFreeMassNoReturn) * (1.0f - occ) : 0.0f;
  const float z_unk = 1.0f - z_occ - z_free;
  const float norm = 1.0f / (1.0f - (o_pred * z_free + f_pred * z_occ));
  const float o_up = (o_pred * (z_occ + z_unk) + u_pred * z_occ) * norm;
  const float f_up = (f_pred * (z_free + z_unk) + u_pred * z_free) * norm;
  const CellSums sums = WeighCell(lo, hi, cap, observed);
  double a_dyn = sums.dyn;
  // Joint normalisation of o_up (eqs. 9-12), the weights normalised on lanes.
  const double l_static = observed || j >= 0 ? std::max(occ * kKeep, (1.0f - occ) * kKeep) : kKeep;
  double a_static = (s_pred + sums.slow) * l_static + 0.3 * kOccupiedMass * occ;
  const double a_birth = kBirthProbability * occ * (1.0f - o_pred);
  if (a_static + a_dyn + a_birth <= 0.0) {  // keep the predicted split
    a_static = s_pred + sums.slow;
    a_dyn = sums.fast;
  }
  const double q = a_static + a_dyn + a_birth;
  const double rho_p = q > 0.0 ? o_up * a_dyn / q : 0.0, rho_b = q > 0.0 ? o_up * a_birth / q : 0.0;
  NormaliseCell(lo, hi, rho_p, sums.pos, sums.vel);
  free_[c] = f_up;
  static_[c] = q > 0.0 ? static_cast<float>(o_up * a_static / q) : 0.0f;
  dynamic_[c] = static_cast<float>(rho_p);
  born_[c] = static_cast<float>(rho_b);
  return rho_b;
}

// Cells [ch kCellChunk, ...): QuietCells, then UpdateCell for the others; the born cells listed.
void FloorCycle::CellChunk(std::int64_t ch) {
  const std::int64_t c_lo = ch * kCellChunk, c_hi = std::min(cells_, c_lo + kCellChunk);
  QuietCells(c_lo, c_hi);
  std::int32_t n_born = 0;
  double born_sum = 0.0;
  for (std::int64_t c = c_lo; c < c_hi; ++c) {
    if (start_[c] == start_[c + 1] && near_[c] < 0) continue;
    const double rho_b = UpdateCell(c);
    if (rho_b > 0.0) {
      born_list_[c_lo + n_born++] = static_cast<std::int32_t>(c);
      born_sum += rho_b;
    }
  }
  born_n_[ch] = n_born;
  chunk_born_[ch + 1] = born_sum;
}

// The born cells of chunk ch: their share of the births by systematic allocation (offset u0 of
// the cumulative born mass), each birth uniform in its cell with the detection's radial speed.
void FloorCycle::BirthChunk(std::int64_t ch, double total, float u0) {
  if (!(total > 0.0)) return;
  double cum = chunk_born_[ch];
  const double scale = nb_ / total;
  alignas(64) std::uint32_t raw[4][64];
  for (std::int32_t t = 0; t < born_n_[ch]; ++t) {
    const std::int32_t c = born_list_[ch * kCellChunk + t];
    const std::int64_t k0 = static_cast<std::int64_t>(std::floor(cum * scale + u0));
    cum += born_[c];
    const std::int64_t k1 = std::min<std::int64_t>(nb_, std::floor(cum * scale + u0));
    const int j = near_[c];
    const float lx = static_cast<float>(c % nx_), ly = static_cast<float>(c / nx_);
    const float w = k1 > k0 ? born_[c] / static_cast<float>(k1 - k0) : 0.0f;
    for (std::int64_t b0 = k0; b0 < k1; b0 += 64) {
      const std::int64_t m = std::min<std::int64_t>(64, k1 - b0);
      filter::detail::PhiloxLanes(seed_, 11, step_, static_cast<std::uint32_t>(b0), m, 0, raw[0],
                                  raw[1], raw[2], raw[3]);
      for (std::int64_t q = 0; q < m; ++q) {
        const std::int64_t i = n_ + b0 + q;
        const auto unit = [&](int a) { return static_cast<float>(raw[a][q] >> 8) * 0x1p-24f; };
        s_.x[i] = (lx + unit(0)) * r_;
        s_.y[i] = (ly + unit(1)) * r_;
        const float vt = kMaxTangential * (2.0f * unit(2) - 1.0f),
                    vr = u2_[j] + 0.5f * (unit(3) - 0.5f);
        s_.vx[i] = vr * u0_[j] - vt * u1_[j];
        s_.vy[i] = vr * u1_[j] + vt * u0_[j];
        s_.weight[i] = s_.w_position[i] = s_.w_velocity[i] = w;
      }
    }
  }
}

// Outputs of input block b: the persistent particles i whose systematic position (i + u0) W / N
// falls in the block's share of the cumulative weight, copied from their source.
void FloorCycle::ResampleBlock(std::int64_t b, double total, double u0) {
  const std::int64_t in = n_ + nb_, lo = b * kSumBlock, hi = std::min(in, lo + kSumBlock);
  const double step = total / n_;
  const auto first_out = [&](double base) {
    return std::clamp<std::int64_t>(static_cast<std::int64_t>(std::ceil(base / step - u0)), 0, n_);
  };
  const std::int64_t i_lo = first_out(block_w_[b]);
  const std::int64_t i_hi = hi == in ? n_ : first_out(block_w_[b + 1]);
  double acc = 0.0;
  std::int64_t j = lo;
  const float w = static_cast<float>(step);
  for (std::int64_t i = i_lo; i < i_hi; ++i) {
    const double pos = (static_cast<double>(i) + u0) * step - block_w_[b];
    while (j < hi - 1 && acc + s_.weight[j] <= pos) acc += s_.weight[j++];
    p_.x[i] = s_.x[j];
    p_.y[i] = s_.y[j];
    p_.vx[i] = s_.vx[j];
    p_.vy[i] = s_.vy[j];
    p_.weight[i] = p_.w_position[i] = p_.w_velocity[i] = w;
  }
}

// Inside Run's parallel region, thread t of nt (after every thread's Predict): the counting
// sort's cell starts and per-thread offsets in fixed blocks of cells, then each thread's stable
// scatter of its chunk (orphaned worksharing: the barriers are the region's).
void FloorCycle::Sort(int t, int nt) {
  const std::int64_t c1 = cells_ + 1, cblocks = (c1 + kCellChunk - 1) / kCellChunk;
#pragma omp for schedule(static)
  for (std::int64_t b = 0; b < cblocks; ++b) {
    std::int32_t sum = 0;
    for (std::int64_t c = b * kCellChunk; c < std::min(c1, (b + 1) * kCellChunk); ++c)
      for (int k = 0; k < nt; ++k) sum += hist_[k * c1 + c];
    block_total_[b + 1] = sum;
  }
#pragma omp single
  {
    block_total_[0] = 0;
    for (std::int64_t b = 0; b < cblocks; ++b) block_total_[b + 1] += block_total_[b];
    start_[c1] = n_;
  }
#pragma omp for schedule(static)
  for (std::int64_t b = 0; b < cblocks; ++b) {
    std::int32_t run = block_total_[b];
    for (std::int64_t c = b * kCellChunk; c < std::min(c1, (b + 1) * kCellChunk); ++c) {
      start_[c] = run;
      for (int k = 0; k < nt; ++k) {
        const std::int32_t count = hist_[k * c1 + c];
        hist_[k * c1 + c] = run;  // thread k's first slot in cell c
        run += count;
      }
    }
  }
  // hist_ now holds each thread's write offsets: the stable scatter of its chunk.
  for (std::int64_t i = static_cast<std::int64_t>(n_) * t / nt;
       i < static_cast<std::int64_t>(n_) * (t + 1) / nt; ++i) {
    filter::CopyParticle(p_, i, s_, hist_[t * c1 + cell_of_[i]]++);
  }
}

void FloorCycle::Run(const Position& centre, std::span<const filter::Measurement> z,
                     std::span<const filter::SensorCoverage> coverage, double dt) {
  ThreadCpu(&mark_);
  Inputs(centre, z, coverage);
  const int threads = omp_get_max_threads();
  if (hist_threads_ < threads) {
    hist_.resize(static_cast<std::size_t>(threads) * (cells_ + 1));
    hist_threads_ = threads;
  }
  const std::int64_t chunks = (cells_ + kCellChunk - 1) / kCellChunk;
  const std::int64_t in = n_ + nb_, sblocks = (in + kSumBlock - 1) / kSumBlock;
  std::uint32_t u[4];
  filter::detail::PhiloxLanes(seed_, 12, step_, 0, 1, 0, &u[0], &u[1], &u[2], &u[3]);
  const float u_birth = static_cast<float>(u[0] >> 8) * 0x1p-24f;
  const double u_res = static_cast<double>(u[1] >> 8) * 0x1p-24;
  double born_total = 0.0, w_total = 0.0;
#pragma omp parallel num_threads(threads)
  {
    const int t = omp_get_thread_num(), nt = omp_get_num_threads();
    MeasurementRows(ny_ * t / nt, ny_ * (t + 1) / nt);
    Mark(t, 0);  // measurement grid
    Predict(t, nt, static_cast<float>(dt));
    Mark(t, 1);  // prediction
#pragma omp barrier
    Sort(t, nt);
    Mark(t, 2);  // sort
#pragma omp barrier
#pragma omp for schedule(static, 1)
    for (std::int64_t ch = 0; ch < chunks; ++ch) CellChunk(ch);
    Mark(t, 3);  // cell pass
#pragma omp single
    {
      chunk_born_[0] = 0.0;
      for (std::int64_t ch = 0; ch < chunks; ++ch) chunk_born_[ch + 1] += chunk_born_[ch];
      born_total = chunk_born_[chunks];
      std::fill_n(s_.weight.begin() + n_, nb_, 0.0f);
      std::fill_n(s_.weight.begin() + start_[cells_], n_ - start_[cells_], 0.0f);  // off the grid
    }
#pragma omp for schedule(static, 1)
    for (std::int64_t ch = 0; ch < chunks; ++ch) BirthChunk(ch, born_total, u_birth);
    Mark(t, 4);  // births
#pragma omp for schedule(static)
    for (std::int64_t b = 0; b < sblocks; ++b) {
      double sum = 0.0;
      for (std::int64_t i = b * kSumBlock; i < std::min(in, (b + 1) * kSumBlock); ++i)
        sum += s_.weight[i];
      block_w_[b + 1] = sum;
    }
#pragma omp single
    {
      block_w_[0] = 0.0;
      for (std::int64_t b = 0; b < sblocks; ++b) block_w_[b + 1] += block_w_[b];
      w_total = block_w_[sblocks];
    }
#pragma omp for schedule(static)
    for (std::int64_t b = 0; b < sblocks; ++b) ResampleBlock(b, w_total, u_res);
    Mark(t, 5);  // resampling
  }
  ++step_;
}

void FloorCycle::Mark(int thread, int phase) {
  if (thread != 0) return;
  const double before = mark_;
  ThreadCpu(&mark_);
  phase_cpu_[phase] += mark_ - before;
}

double FloorCycle::DynamicMass() const {
  double s = 0.0;
  for (std::int64_t c = 0; c < cells_; ++c) s += dynamic_[c];
  return s;
}

std::int64_t FloorCycle::CellsWithParticles() const {
  std::int64_t n = 0;
  for (std::int64_t c = 0; c < cells_; ++c) n += start_[c + 1] > start_[c] ? 1 : 0;
  return n;
}

std::int64_t FloorCycle::CellsWithDetection() const {
  return std::count_if(near_.begin(), near_.begin() + cells_, [](int j) { return j >= 0; });
}

}  // namespace dualgrid::bench
