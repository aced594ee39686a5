#include "dualgrid/filter/dynamic_grid.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include <omp.h>

#include "dualgrid/core/random.hpp"
#include "fast_normal.hpp"
#include "predict.hpp"

namespace dualgrid::filter {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
// Bits of view_: in a field of view; in front of a detection on its ray; in a bin without returns.
constexpr std::uint8_t kObserved = 1, kFreeRay = 2, kNoReturn = 4;
// Chunks of the counting sort; the sorted order is the same for any chunk count (stable sort).
constexpr int kMaxSortChunks = 8;

std::int64_t Mod(std::int64_t a, std::int64_t b) {
  const std::int64_t r = a % b;
  return r < 0 ? r + b : r;
}

// atan2 with |error| < 2.1e-4 rad (measured 2.04e-4): bearing bins are ~1e-2 rad wide, and
// std::atan2 per cell and sensor dominated the free-space pass.
inline double FastAtan2(double y, double x) {
  const double ax = std::abs(x), ay = std::abs(y);
  const double mx = std::max(ax, ay), mn = std::min(ax, ay);
  if (mx == 0.0) return 0.0;
  const double a = mn / mx, s = a * a;
  double r = ((-0.0464964749 * s + 0.15931422) * s - 0.327622764) * s * a + a;
  if (ay > ax) r = 0.5 * kPi - r;
  if (x < 0.0) r = kPi - r;
  return y < 0.0 ? -r : r;
}

// std::exp with the underflow range short-cut: glibc takes a slow path (errno handling) below
// ~-103.97 (float) / ~-745.13 (double), where the correctly rounded result is +0 anyway.
inline float ExpUnder(float x) { return x < -104.0f ? 0.0f : std::exp(x); }
inline double ExpUnder(double x) { return x < -746.0 ? 0.0 : std::exp(x); }

// Bound on |FastAtan2 - atan2| (measured 2.04e-4 rad at the octant boundary), with margin.
constexpr double kAtanError = 5e-4;

// Exclusive prefix sum over the concatenation of a[0..na) and b[0..n - na) (floats, summed in
// double) into out[0..n], with exactly the summation order of ExclusiveScan (particles.cpp: blocks
// of kScanBlock, block totals, serial scan, local scans): bit-identical to it, without
// materialising the concatenated input.
constexpr std::int64_t kScanBlock = 1 << 14;
// Cells per UpdateCells work item; divides kScanBlock (Birth walks the per-chunk birth lists).
constexpr std::int64_t kCellChunk = 512;
static_assert(kScanBlock % kCellChunk == 0);
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
#pragma omp parallel for schedule(static)
  for (std::int64_t k = 0; k < blocks; ++k) {
    const std::int64_t lo = k * kScanBlock, hi = std::min(n, lo + kScanBlock);
    tot[k + 1] = block_sum(lo, hi, 0.0);
  }
  tot[0] = 0.0;
  for (std::int64_t k = 0; k < blocks; ++k) tot[k + 1] += tot[k];
#pragma omp parallel for schedule(static)
  for (std::int64_t k = 0; k < blocks; ++k) {
    const std::int64_t lo = k * kScanBlock, hi = std::min(n, lo + kScanBlock);
    block_scan(lo, hi, tot[k]);
  }
  out[n] = tot[blocks];
}

// static_cast<int64>(std::ceil(x)) for finite |x| < 2^62 (no libm call without SSE4.1).
inline std::int64_t CeilToInt(double x) {
  const std::int64_t i = static_cast<std::int64_t>(x);  // truncation towards zero
  return static_cast<double>(i) < x ? i + 1 : i;
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

DynamicGrid::DynamicGrid(const FilterParams& params, std::uint64_t seed)
    : params_(params), seed_(seed) {
  std::string error;
  if (!params_.IsValid(&error)) {
    throw std::invalid_argument("dualgrid::filter::DynamicGrid: invalid FilterParams: " + error);
  }
  nx_ = params_.CellsX();
  ny_ = params_.CellsY();
  num_cells_ = static_cast<std::int64_t>(nx_) * ny_;
  const auto c = static_cast<std::size_t>(num_cells_);
  for (auto* v : {&free_, &static_, &dynamic_, &born_}) v->assign(c, 0.0);
  view_.assign(c, 0);
  near_det_.assign(c, -1);
  near_d2_.assign(c, kInf);
  touched_.reserve(4096);
  const auto n = static_cast<std::size_t>(params_.num_particles);
  const auto b = static_cast<std::size_t>(params_.num_birth);
  particles_.resize(n);
  sorted_.resize(n);
  births_.resize(b);
  cell_of_.assign(n, 0);
  cell_start_.assign(c + 2, 0);
  born_cells_.assign(c, 0);
  born_count_.assign(static_cast<std::size_t>((num_cells_ + kCellChunk - 1) / kCellChunk), 0);
  born_chunk_acc_.assign(born_count_.size(), 0.0);
  hist_total_.assign(static_cast<std::size_t>(num_cells_ / (1 << 10) + 2), 0);
  hist_.assign(static_cast<std::size_t>(kMaxSortChunks) * (c + 1), 0);
  scan_out_.assign(n + b + 1, 0.0);
  const double cutoff = params_.cutoff_sigmas * params_.sigma_f;
  // Buckets at least cutoff + one cell wide: every detection within the cutoff of any point of a
  // cell lies in the 3 x 3 buckets around any particle of that cell (UpdateCells relies on it).
  bucket_cells_ = static_cast<int>(std::ceil(cutoff / params_.resolution)) + 1;
  nbx_ = (nx_ + bucket_cells_ - 1) / bucket_cells_;
  nby_ = (ny_ + bucket_cells_ - 1) / bucket_cells_;
  bucket_count_.assign(static_cast<std::size_t>(nbx_) * nby_, 0);
  bucket_start_.assign(static_cast<std::size_t>(nbx_) * nby_ + 1, 0);
}

std::int64_t DynamicGrid::Storage(std::int64_t gx, std::int64_t gy) const {
  return Mod(gy, ny_) * nx_ + Mod(gx, nx_);
}

Position DynamicGrid::CellCenter(CellIndex c) const {
  const double r = params_.resolution;
  return {(static_cast<double>(origin_gx_ + c.x) + 0.5) * r,
          (static_cast<double>(origin_gy_ + c.y) + 0.5) * r};
}

std::optional<CellIndex> DynamicGrid::CellOf(const Position& p) const {
  if (!initialized_ || !p.allFinite()) return std::nullopt;
  const double r = params_.resolution;
  const double fx = std::floor(p.x() / r) - static_cast<double>(origin_gx_);
  const double fy = std::floor(p.y() / r) - static_cast<double>(origin_gy_);
  if (fx < 0.0 || fy < 0.0 || fx >= nx_ || fy >= ny_) return std::nullopt;
  return CellIndex{static_cast<int>(fx), static_cast<int>(fy)};
}

CellState DynamicGrid::Cell(CellIndex c) const {
  if (c.x < 0 || c.y < 0 || c.x >= nx_ || c.y >= ny_) {
    throw std::out_of_range("DynamicGrid::Cell: index (" + std::to_string(c.x) + ", " +
                            std::to_string(c.y) + ") outside " + std::to_string(nx_) + " x " +
                            std::to_string(ny_));
  }
  const std::int64_t s = Storage(origin_gx_ + c.x, origin_gy_ + c.y);
  CellState out;
  out.free = free_[s];
  out.static_occ = static_[s];
  out.dynamic = dynamic_[s];
  out.unknown = std::max(0.0, 1.0 - out.free - out.static_occ - out.dynamic);
  // Velocity statistics on demand from the weighted particles of the last update (sorted_ and
  // its cell ranges stay valid until the next Update): saves five layers of memory traffic.
  double wsum = 0.0, mx = 0.0, my = 0.0;
  for (std::int64_t i = cell_start_[s]; i < cell_start_[s + 1]; ++i) {
    wsum += sorted_.weight[i];
    mx += sorted_.weight[i] * static_cast<double>(sorted_.vx[i]);
    my += sorted_.weight[i] * static_cast<double>(sorted_.vy[i]);
  }
  if (wsum > 0.0) {
    out.mean_velocity = {mx / wsum, my / wsum};
    Matrix2 cov = Matrix2::Zero();
    for (std::int64_t i = cell_start_[s]; i < cell_start_[s + 1]; ++i) {
      const Vector2 e(sorted_.vx[i] - out.mean_velocity.x(), sorted_.vy[i] - out.mean_velocity.y());
      cov += sorted_.weight[i] * e * e.transpose();
    }
    out.velocity_cov = cov / wsum;
  }
  out.observed = (view_[s] & kObserved) != 0;
  return out;
}

void DynamicGrid::Initialize(const EgoInput& ego) {
  const double r = params_.resolution;
  origin_gx_ = static_cast<std::int64_t>(std::floor(ego.pose.position.x() / r)) - nx_ / 2;
  origin_gy_ = static_cast<std::int64_t>(std::floor(ego.pose.position.y() / r)) - ny_ / 2;
  // Particles start spread over the grid with zero weight: the first births replace them.
  const double x0 = static_cast<double>(origin_gx_) * r, y0 = static_cast<double>(origin_gy_) * r;
  const std::int64_t n = static_cast<std::int64_t>(particles_.size());
#pragma omp parallel for schedule(static)
  for (std::int64_t i = 0; i < n; ++i) {
    CounterRng rng(seed_, RngPurpose::kFilterInit, 0, static_cast<std::uint32_t>(i));
    particles_.x[i] = x0 + rng.Uniform() * nx_ * r;
    particles_.y[i] = y0 + rng.Uniform() * ny_ * r;
    particles_.vx[i] = particles_.vy[i] = 0.0;
    particles_.w_position[i] = particles_.w_velocity[i] = particles_.weight[i] = 0.0;
  }
  initialized_ = true;
}

void DynamicGrid::ResetColumn(std::int64_t gx) {
  const std::int64_t sx = Mod(gx, nx_);
  for (std::int64_t sy = 0; sy < ny_; ++sy) {
    const std::int64_t s = sy * nx_ + sx;
    free_[s] = static_[s] = dynamic_[s] = 0.0;
  }
}

void DynamicGrid::ResetRow(std::int64_t gy) {
  const std::int64_t sy = Mod(gy, ny_);
  std::fill_n(free_.begin() + sy * nx_, nx_, 0.0);
  std::fill_n(static_.begin() + sy * nx_, nx_, 0.0);
  std::fill_n(dynamic_.begin() + sy * nx_, nx_, 0.0);
}

void DynamicGrid::ShiftTo(const Position& ego) {
  const double r = params_.resolution;
  const std::int64_t gx = static_cast<std::int64_t>(std::floor(ego.x() / r)) - nx_ / 2;
  const std::int64_t gy = static_cast<std::int64_t>(std::floor(ego.y() / r)) - ny_ / 2;
  const std::int64_t dx = gx - origin_gx_, dy = gy - origin_gy_;
  // Only the storage columns/rows that now represent new world cells are cleared (grid_map
  // style); everything else stays in place and is re-addressed through the new origin.
  if (std::abs(dx) >= nx_ || std::abs(dy) >= ny_) {
    std::fill(free_.begin(), free_.end(), 0.0);
    std::fill(static_.begin(), static_.end(), 0.0);
    std::fill(dynamic_.begin(), dynamic_.end(), 0.0);
  } else {
    for (std::int64_t c = 0; c < std::abs(dx); ++c)
      ResetColumn(dx > 0 ? origin_gx_ + nx_ + c : gx + c);
    for (std::int64_t c = 0; c < std::abs(dy); ++c)
      ResetRow(dy > 0 ? origin_gy_ + ny_ + c : gy + c);
  }
  origin_gx_ = gx;
  origin_gy_ = gy;
}

void DynamicGrid::PredictAndSort(double dt) {
  const float sp = static_cast<float>(params_.process_noise_position * std::sqrt(dt));
  const float sv = static_cast<float>(params_.process_noise_velocity * std::sqrt(dt));
  const std::int64_t n = static_cast<std::int64_t>(particles_.size());
  const std::int64_t c1 = num_cells_ + 1;  // bucket num_cells_ collects particles off the grid
  const double inv_r = 1.0 / params_.resolution;
  const std::int64_t sx0 = Mod(origin_gx_, nx_), sy0 = Mod(origin_gy_, ny_);
  const int chunks = std::clamp(omp_get_max_threads(), 1, kMaxSortChunks);
  // Blocks of cells for pass 2 (small enough to balance two threads at the paper size).
  constexpr std::int64_t kCellBlock = 1 << 10;
  const std::int64_t nblocks = (c1 + kCellBlock - 1) / kCellBlock;
  if (static_cast<std::int64_t>(hist_total_.size()) < nblocks + 1) hist_total_.resize(nblocks + 1);
  std::int64_t* block_base = hist_total_.data();
  // All passes in one parallel region (the implicit barriers of the worksharing loops order them).
#pragma omp parallel
  {
    // Counting sort, stable: particle order within a cell = order before sorting, for any chunking.
    // Pass 1 (per chunk): prediction (step 2, batch by batch while the batch is in cache), storage
    // cell of each particle and the chunk's histogram.
#pragma omp for schedule(static)
    for (int k = 0; k < chunks; ++k) {
      std::int32_t* h = hist_.data() + k * c1;
      std::fill_n(h, c1, 0);
      const std::int64_t chunk_hi = (k + 1) * n / chunks;
      for (std::int64_t b0 = k * n / chunks; b0 < chunk_hi; b0 += detail::kPredictBlock) {
        const std::int64_t b1 = std::min(chunk_hi, b0 + detail::kPredictBlock);
        detail::PredictRange(particles_, b0, b1, dt, sp, sv, params_.persistence, seed_, step_);
        for (std::int64_t i = b0; i < b1; ++i) {
          const double fx = std::floor(particles_.x[i] * inv_r) - static_cast<double>(origin_gx_);
          const double fy = std::floor(particles_.y[i] * inv_r) - static_cast<double>(origin_gy_);
          const bool inside = fx >= 0.0 && fy >= 0.0 && fx < nx_ && fy < ny_;  // false for NaN too
          std::int64_t c = num_cells_;
          if (inside) {
            // Storage index without integer division (hot loop): wrap once.
            std::int64_t sx = sx0 + static_cast<std::int64_t>(fx);
            std::int64_t sy = sy0 + static_cast<std::int64_t>(fy);
            if (sx >= nx_) sx -= nx_;
            if (sy >= ny_) sy -= ny_;
            c = sy * nx_ + sx;
          }
          cell_of_[i] = c;
          ++h[c];
        }
      }
    }
    // Pass 2: cell starts and per-chunk write offsets in fixed blocks of cells (integers: exact in
    // any order). Block totals first, then a serial scan over blocks, then the offsets.
#pragma omp for schedule(static)
    for (std::int64_t b = 0; b < nblocks; ++b) {
      const std::int64_t lo = b * kCellBlock, hi = std::min(c1, lo + kCellBlock);
      std::int64_t t = 0;
      for (int k = 0; k < chunks; ++k) {
        const std::int32_t* h = hist_.data() + k * c1;
        for (std::int64_t c = lo; c < hi; ++c) t += h[c];
      }
      block_base[b + 1] = t;
    }
#pragma omp single
    {
      block_base[0] = 0;
      for (std::int64_t b = 0; b < nblocks; ++b) block_base[b + 1] += block_base[b];
      cell_start_[c1] = n;
    }
#pragma omp for schedule(static)
    for (std::int64_t b = 0; b < nblocks; ++b) {
      const std::int64_t lo = b * kCellBlock, hi = std::min(c1, lo + kCellBlock);
      std::int64_t run = block_base[b];
      for (std::int64_t c = lo; c < hi; ++c) {
        cell_start_[c] = run;
        for (int k = 0; k < chunks; ++k) {
          const std::int64_t t = hist_[k * c1 + c];
          hist_[k * c1 + c] = static_cast<std::int32_t>(run);
          run += t;
        }
      }
    }
#pragma omp for schedule(static)
    for (int k = 0; k < chunks; ++k) {
      std::int32_t* h = hist_.data() + k * c1;
      for (std::int64_t i = k * n / chunks; i < (k + 1) * n / chunks; ++i) {
        sorted_.CopyFrom(particles_, i, h[cell_of_[i]]++);
      }
    }
  }
}

void DynamicGrid::BuildMeasurementGrid(std::span<const Measurement> z,
                                       std::span<const SensorCoverage> cov) {
  const double r = params_.resolution;
  const double cutoff = params_.cutoff_sigmas * params_.sigma_f, cutoff2 = cutoff * cutoff;
  const int rc = static_cast<int>(std::ceil(cutoff / r));
  for (std::int64_t s : touched_) {
    near_det_[s] = -1;
    near_d2_[s] = kInf;
  }
  touched_.clear();

  // Nearest detection per cell centre, stamped detection by detection (serial, so ties resolve
  // to the lower index whatever the thread count). Also fills the detection buckets.
  std::fill(bucket_count_.begin(), bucket_count_.end(), 0);
  const int nz = static_cast<int>(z.size());
  if (static_cast<int>(det_bucket_.size()) < nz) det_bucket_.resize(nz);  // grows only
  std::vector<std::int64_t>& bucket_of = det_bucket_;
  for (int j = 0; j < nz; ++j) {
    bucket_of[j] = -1;
    const Position& p = z[j].position;
    if (!p.allFinite() || !z[j].radial_velocity.allFinite()) continue;
    const double fx = std::floor(p.x() / r) - static_cast<double>(origin_gx_);
    const double fy = std::floor(p.y() / r) - static_cast<double>(origin_gy_);
    if (fx < -rc || fy < -rc || fx >= nx_ + rc || fy >= ny_ + rc) continue;
    const int lx = static_cast<int>(fx), ly = static_cast<int>(fy);
    const auto [bx, by] = BucketOf(p.x(), p.y());
    bucket_of[j] = static_cast<std::int64_t>(by) * nbx_ + bx;
    ++bucket_count_[bucket_of[j]];
    const std::int64_t sx0 = Mod(origin_gx_, nx_);
    for (int cy = std::max(0, ly - rc); cy <= std::min(ny_ - 1, ly + rc); ++cy) {
      const std::int64_t row = Mod(origin_gy_ + cy, ny_) * nx_;  // one division per row
      const double ey = (static_cast<double>(origin_gy_ + cy) + 0.5) * r - p.y();
      for (int cx = std::max(0, lx - rc); cx <= std::min(nx_ - 1, lx + rc); ++cx) {
        const double ex = (static_cast<double>(origin_gx_ + cx) + 0.5) * r - p.x();
        const double d2 = ex * ex + ey * ey;
        if (d2 > cutoff2) continue;
        const std::int64_t sx = sx0 + cx;
        const std::int64_t s = row + (sx >= nx_ ? sx - nx_ : sx);
        if (near_det_[s] < 0) touched_.push_back(s);
        if (d2 < near_d2_[s]) {
          near_d2_[s] = d2;
          near_det_[s] = j;
        }
      }
    }
  }
  const std::int64_t nb = static_cast<std::int64_t>(nbx_) * nby_;
  ExclusiveScan(std::span<const std::int64_t>(bucket_count_.data(), nb),
                std::span<std::int64_t>(bucket_start_.data(), nb + 1));
  if (static_cast<int>(bucket_items_.size()) < nz) {  // grows only
    bucket_items_.resize(nz);
    det_x_.resize(nz);
    det_y_.resize(nz);
  }
  std::fill(bucket_count_.begin(), bucket_count_.end(), 0);
  for (int j = 0; j < nz; ++j) {
    if (bucket_of[j] < 0) continue;
    const std::int64_t k = bucket_start_[bucket_of[j]] + bucket_count_[bucket_of[j]]++;
    bucket_items_[k] = j;
    det_x_[k] = z[j].position.x();
    det_y_[k] = z[j].position.y();
  }

  // Bearing bins per sensor: range of the closest detection shadowing each bin.
  const int ns = static_cast<int>(cov.size());
  bin_offset_.assign(ns + 1, 0);  // small vectors; capacity is reused across cycles
  for (int s = 0; s < ns; ++s) {
    const int bins =
        std::max(1, static_cast<int>(std::ceil(2.0 * cov[s].half_fov / params_.free_angle_bin)));
    bin_offset_[s + 1] = bin_offset_[s] + bins;
  }
  bin_range_.assign(bin_offset_[ns], kInf);
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

  // Field of view and ray free space per cell (rows in parallel: each cell has one writer).
  const double x0 = static_cast<double>(origin_gx_) * r, y0 = static_cast<double>(origin_gy_) * r;
  const std::int64_t sx0 = Mod(origin_gx_, nx_);
  // Per-sensor trigonometry once per cycle, not per row.
  sensor_trig_.resize(4 * static_cast<std::size_t>(ns));
  for (int k = 0; k < ns; ++k) {
    sensor_trig_[4 * k] = std::cos(cov[k].boresight);
    sensor_trig_[4 * k + 1] = std::sin(cov[k].boresight);
    sensor_trig_[4 * k + 2] = cov[k].half_fov < 0.5 * kPi ? std::tan(cov[k].half_fov) : 0.0;
    // Inner wedge (half_fov - 4 kAtanError): its cells pass the segment test below at once.
    const double inner = cov[k].half_fov - 4.0 * kAtanError;
    sensor_trig_[4 * k + 3] = inner > 0.0 && cov[k].half_fov < 0.5 * kPi ? std::tan(inner) : -1.0;
  }
  // Last bin of the run of equal ranges each bin belongs to (per sensor): O(1) uniformity test.
  bin_run_end_.resize(bin_range_.size());
  for (int k = 0; k < ns; ++k) {
    const std::int64_t b_lo = bin_offset_[k], b_hi = bin_offset_[k + 1];
    for (std::int64_t b = b_hi - 1; b >= b_lo; --b) {
      bin_run_end_[b] = b + 1 < b_hi && bin_range_[b + 1] == bin_range_[b]
                            ? bin_run_end_[b + 1]
                            : static_cast<int>(b - b_lo);
    }
  }
#pragma omp parallel for schedule(dynamic, 2)
  for (int ly = 0; ly < ny_; ++ly) {
    const std::int64_t row = Mod(origin_gy_ + ly, ny_) * nx_;
    const double cy = y0 + (ly + 0.5) * r;
    std::fill_n(view_.begin() + row, nx_, 0);  // whole storage row = whole logical row
    for (int k = 0; k < ns; ++k) {
      const SensorCoverage& sc = cov[k];
      const double dy = cy - sc.origin.y();
      if (std::abs(dy) > sc.max_range) continue;
      const double half_x = std::sqrt(sc.max_range * sc.max_range - dy * dy);
      const int lx_lo =
          std::max(0, static_cast<int>(std::floor((sc.origin.x() - half_x - x0) / r)));
      const int lx_hi =
          std::min(nx_ - 1, static_cast<int>(std::floor((sc.origin.x() + half_x - x0) / r)));
      // Sensor frame (fx along the boresight): the field-of-view test needs no atan2 when
      // half_fov < 90 deg; atan2 only runs for cells inside the field of view (for the bin).
      const double cb = sensor_trig_[4 * k], sb = sensor_trig_[4 * k + 1];
      const bool narrow = sc.half_fov < 0.5 * kPi;
      const double tan_hf = sensor_trig_[4 * k + 2], tan_in = sensor_trig_[4 * k + 3];
      const int* const run_end = bin_run_end_.data() + bin_offset_[k];
      const double min2 = sc.min_range * sc.min_range, max2 = sc.max_range * sc.max_range;
      const double* bins = bin_range_.data() + bin_offset_[k];
      const int nbins = static_cast<int>(bin_offset_[k + 1] - bin_offset_[k]);
      const double inv_bin = 1.0 / params_.free_angle_bin;
      const double ax = x0 + 0.5 * r - sc.origin.x();  // dx of cell lx = ax + lx * r
      // Exact per-cell test (the reference definition of the bits).
      const auto exact = [&](int lx) {
        const double dx = x0 + (lx + 0.5) * r - sc.origin.x();
        const double d2 = dx * dx + dy * dy;
        if (d2 < min2 || d2 > max2) return;
        const double fx = dx * cb + dy * sb, fy = dy * cb - dx * sb;
        if (narrow && (fx <= 0.0 || std::abs(fy) > fx * tan_hf)) return;
        const double rel = FastAtan2(fy, fx);
        if (std::abs(rel) > sc.half_fov) return;
        const std::int64_t sx = sx0 + lx;
        const std::int64_t s = row + (sx >= nx_ ? sx - nx_ : sx);
        const int b = std::clamp(static_cast<int>((rel + sc.half_fov) * inv_bin), 0, nbins - 1);
        const double br = bins[b];
        // Free in front of the bin's closest detection, unknown behind it; a bin without any
        // detection is weakly free over the whole range.
        view_[s] |= static_cast<std::uint8_t>(kObserved | (br == kInf ? kNoReturn : 0) |
                                              (br != kInf && d2 < br * br ? kFreeRay : 0));
      };
      int lo_x = lx_lo, hi_x = lx_hi;
      // Cells inside a wedge of half angle atan(tan_w) satisfy three linear conditions in dx
      // (fx > 0, fx tan - fy >= 0, fx tan + fy >= 0): their interval of dx.
      const auto wedge = [&](double tan_w, double* dmin, double* dmax) {
        *dmin = -kInf;
        *dmax = kInf;
        for (const auto& [c, d] :
             {std::pair{cb, dy * sb}, std::pair{cb * tan_w + sb, dy * (sb * tan_w - cb)},
              std::pair{cb * tan_w - sb, dy * (sb * tan_w + cb)}}) {
          if (c > 0.0) {
            *dmin = std::max(*dmin, -d / c);
          } else if (c < 0.0) {
            *dmax = std::min(*dmax, -d / c);
          } else if (d < 0.0) {
            *dmax = -kInf;
          }
        }
        return *dmin <= *dmax;
      };
      const double big = 4.0 * nx_;
      int in_lo = 1, in_hi = 0;  // cells well inside the wedge (empty unless narrow)
      if (narrow) {
        // Clip the row to the wedge, two cells of margin (the exact test still decides every
        // cell).
        double dmin, dmax;
        if (!wedge(tan_hf, &dmin, &dmax)) continue;
        const double l0 = std::clamp(std::floor((dmin - ax) / r) - 2.0, -big, big);
        const double l1 = std::clamp(std::ceil((dmax - ax) / r) + 2.0, -big, big);
        lo_x = std::max(lo_x, static_cast<int>(l0));
        hi_x = std::min(hi_x, static_cast<int>(l1));
        // The cells of the inner wedge (half_fov - 4 kAtanError, one cell of margin) pass the
        // field-of-view part of the segment test below: segmenting the row there first saves the
        // bisection down to the wedge edges. Only the segmentation changes, not any cell's bits.
        if (tan_in > 0.0 && wedge(tan_in, &dmin, &dmax)) {
          in_lo = std::max(
              lo_x, static_cast<int>(std::clamp(std::ceil((dmin - ax) / r) + 1.0, -big, big)));
          in_hi = std::min(
              hi_x, static_cast<int>(std::clamp(std::floor((dmax - ax) / r) - 1.0, -big, big)));
        }
      }
      if (lo_x > hi_x) continue;
      // Segments of the row: the true bearing is monotonic along a row where fx > 0, and FastAtan2
      // is within kAtanError of it, so the cells' computed bearings lie within 2 kAtanError of the
      // hull of the end points' ones and their bins (a monotonic function of the bearing) within
      // the bins of that hull. If all those bins hold the same range, every cell gets the same bin
      // value as in the exact test without its atan2; otherwise the segment is split.
      const auto rel_of = [&](int lx, double* fx_out) {
        const double dxe = x0 + (lx + 0.5) * r - sc.origin.x();
        const double fx = dxe * cb + dy * sb, fy = dy * cb - dxe * sb;
        *fx_out = fx;
        return FastAtan2(fy, fx);
      };
      int stack[128][2];
      int top = 0;
      if (in_lo <= in_hi) {
        for (const auto& [sa, se] :
             {std::pair{lo_x, in_lo - 1}, std::pair{in_lo, in_hi}, std::pair{in_hi + 1, hi_x}}) {
          if (sa > se) continue;
          stack[top][0] = sa;
          stack[top][1] = se;
          ++top;
        }
      } else {
        stack[top][0] = lo_x;
        stack[top][1] = hi_x;
        ++top;
      }
      while (top > 0) {
        --top;
        const int a = stack[top][0], e = stack[top][1];
        if (e - a < 4) {
          for (int lx = a; lx <= e; ++lx) exact(lx);
          continue;
        }
        double fxa, fxe;
        const double ra = rel_of(a, &fxa), re = rel_of(e, &fxe);
        const double lo = std::min(ra, re) - 2.0 * kAtanError,
                     hi = std::max(ra, re) + 2.0 * kAtanError;
        bool uniform = fxa > 0.0 && fxe > 0.0 && lo >= -sc.half_fov && hi <= sc.half_fov;
        double br = kInf;
        if (uniform) {
          const int b0 = std::clamp(static_cast<int>((lo + sc.half_fov) * inv_bin), 0, nbins - 1);
          const int b1 = std::clamp(static_cast<int>((hi + sc.half_fov) * inv_bin), 0, nbins - 1);
          br = bins[b0];
          uniform = run_end[b0] >= b1;
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
        // Branch-free over the segment (vectorises), split where the storage row wraps.
        const std::uint8_t bits_in = br == kInf ? (kObserved | kNoReturn) : kObserved;
        const std::uint8_t bits_front = br == kInf ? bits_in : (kObserved | kFreeRay);
        const double br2 = br * br;
        const int wrap = static_cast<int>(nx_ - sx0);  // first lx whose storage column wraps
        for (int part = 0; part < 2; ++part) {
          const int pa = part == 0 ? a : std::max(a, wrap);
          const int pe = part == 0 ? std::min(e, wrap - 1) : e;
          std::uint8_t* dst = view_.data() + row + sx0 - (part == 0 ? 0 : nx_);
          for (int lx = pa; lx <= pe; ++lx) {
            const double dx = x0 + (lx + 0.5) * r - sc.origin.x();
            const double d2 = dx * dx + dy * dy;
            const double fx = dx * cb + dy * sb, fy = dy * cb - dx * sb;
            const bool in = (d2 >= min2) & (d2 <= max2) &
                            ((!narrow) | ((fx > 0.0) & (std::abs(fy) <= fx * tan_hf)));
            const std::uint8_t v = d2 < br2 ? bits_front : bits_in;
            dst[lx] |= in ? v : 0;
          }
        }
      }
    }
  }
}

std::pair<int, int> DynamicGrid::BucketOf(double px, double py) const {
  // Same formula for detections and queries.
  const double inv = 1.0 / (bucket_cells_ * params_.resolution);
  const double x0 = static_cast<double>(origin_gx_) * params_.resolution;
  const double y0 = static_cast<double>(origin_gy_) * params_.resolution;
  const double fx = std::clamp(std::floor((px - x0) * inv), 0.0, nbx_ - 1.0);
  const double fy = std::clamp(std::floor((py - y0) * inv), 0.0, nby_ - 1.0);
  return {static_cast<int>(fx), static_cast<int>(fy)};
}

void DynamicGrid::UpdateCells(std::span<const Measurement> z) {
  const FilterParams& p = params_;
  const double inv_2sf2 = 0.5 / (p.sigma_f * p.sigma_f);
  const double inv_sd2 = 1.0 / (p.sigma_static_distance * p.sigma_static_distance);
  const double inv_sv2 = 1.0 / (p.sigma_static_velocity * p.sigma_static_velocity);
  const double inv_2v2 = 0.5 / (p.sigma_v * p.sigma_v);
  const double keep = 1.0 - p.decay_eps;
  const double slow2 = p.static_speed * p.static_speed;
  const double max_speed2 = p.max_speed * p.max_speed;
  const double cutoff = p.cutoff_sigmas * p.sigma_f, cutoff2 = cutoff * cutoff;
  ParticleSet& q = sorted_;
  // f_v of the static hypothesis (v = 0) per detection: once per detection, not per cell.
  const int nz = static_cast<int>(z.size());
  if (static_cast<int>(det_fv0_.size()) < nz) det_fv0_.resize(nz);  // grows only
  for (int j = 0; j < nz; ++j) {
    det_fv0_[j] = ExpUnder(-z[j].radial_velocity.squaredNorm() * inv_2v2);
  }
  const double* const fv0_of = det_fv0_.data();
  const double fm = p.free_mass * (1.0 - 0.0), fm_nr = p.free_mass_no_return * (1.0 - 0.0);
  const double static_persistence = p.static_persistence, free_decay = p.free_decay;
  const std::int64_t* const start = cell_start_.data();
  const int* const near = near_det_.data();
  const std::uint8_t* const view_bits = view_.data();
  double* const free_l = free_.data();
  double* const static_l = static_.data();
  double* const dynamic_l = dynamic_.data();
  // Blocks of cells in parallel; dynamic scheduling only balances load, every value is computed by
  // one thread from the same inputs, so results do not depend on the thread count.
  const std::int64_t chunks = (num_cells_ + kCellChunk - 1) / kCellChunk;
#pragma omp parallel for schedule(dynamic, 1)
  for (std::int64_t ch = 0; ch < chunks; ++ch) {
    const std::int64_t c_lo = ch * kCellChunk, c_hi = std::min(num_cells_, c_lo + kCellChunk);
    // Fast path (most cells): no particle, no detection. The general equations below reduce to a
    // free/static Dempster update with the whole occupied mass static and no dynamic mass (same
    // operations with d_pred = 0, occ_k = 0). Branch-free over the block so that it vectorises;
    // the other cells keep their values here and are updated in the loop below.
    for (std::int64_t s = c_lo; s < c_hi; ++s) {
      const bool fast = (start[s] == start[s + 1]) & (near[s] < 0);
      const std::uint8_t view = view_bits[s];
      // z_free of the general path, as 0/1 selectors (fm * 1 + fm_nr * 0 = fm exactly).
      const int obs = view & kObserved, ray = (view >> 1) & 1, none = (view >> 2) & 1;
      const double z_free =
          static_cast<double>(obs & ray) * fm + static_cast<double>(obs & (ray ^ 1) & none) * fm_nr;
      const double st = static_l[s], fr = free_l[s];
      const double s_pred = std::min(static_persistence * st, 1.0 - 0.0);
      const double f_pred = std::max(0.0, std::min(free_decay * fr, 1.0 - 0.0 - s_pred));
      const double o_pred = 0.0 + s_pred;
      const double u_pred = std::max(0.0, 1.0 - o_pred - f_pred);
      const double norm0 = 1.0 / (1.0 - s_pred * z_free);
      const double nf = (f_pred + u_pred * z_free) * norm0;
      const double ns = s_pred * (1.0 - z_free) * norm0;
      free_l[s] = fast ? nf : fr;
      static_l[s] = fast ? ns : st;
      dynamic_l[s] = fast ? 0.0 : dynamic_l[s];
    }
    // Cells with birth mass, in cell order (Birth reads only these).
    std::int64_t* const born_list = born_cells_.data() + c_lo;
    std::int32_t n_born = 0;
    for (std::int64_t s = c_lo; s < c_hi; ++s) {
      const std::int64_t lo = start[s], hi = start[s + 1];
      if (lo == hi && near[s] < 0) continue;  // done above
      const std::uint8_t view = view_[s];
      const bool observed = (view & kObserved) != 0;

      // --- Prediction: predicted masses (dynamic = sum of persistent particle weights). ---
      double d_pred = 0.0;
      for (std::int64_t i = lo; i < hi; ++i) d_pred += q.weight[i];
      const double cap = d_pred > 1.0 ? 1.0 / d_pred : 1.0;  // dynamic mass is a probability
      d_pred *= cap;
      const double s_pred = std::min(p.static_persistence * static_[s], 1.0 - d_pred);
      const double f_pred = std::max(0.0, std::min(p.free_decay * free_[s], 1.0 - d_pred - s_pred));
      const double o_pred = d_pred + s_pred;
      const double u_pred = std::max(0.0, 1.0 - o_pred - f_pred);

      // --- Measurement grid: occupied (f_d, eq. 2), static (eq. 4), free (eq. 3 on rays). ---
      double occ_k = 0.0, static_k = 0.0;
      const int j = near_det_[s];
      if (j >= 0) {
        const double d2 = near_d2_[s];
        occ_k = std::exp(-d2 * inv_2sf2);
        static_k = ExpUnder(-0.5 * (d2 * inv_sd2 + z[j].radial_velocity.squaredNorm() * inv_sv2));
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

      // --- Particle weights, eqs. (7) and (8), unnormalised. The per-cycle factors double as the
      // likelihood of each hypothesis in the joint normalisation below. ---
      const auto mode_factor = [&](double lp, double lv) {
        return p.mode == WeightMode::kPosition   ? lp
               : p.mode == WeightMode::kVelocity ? lv
                                                 : std::max(lp, lv);  // eq. (14)
      };
      double slow_mass = 0.0, fast_mass = 0.0, sum_pos = 0.0, sum_vel = 0.0, a_dyn = 0.0;
      // Candidate detections of all particles of the cell: the three contiguous item ranges of the
      // 3 x 3 buckets around its first particle (buckets are >= cutoff + one cell wide).
      std::int64_t cand[3][2] = {{0, 0}, {0, 0}, {0, 0}};
      bool any_candidate = false;
      if (hi > lo) {
        const auto [bx, by] = BucketOf(q.x[lo], q.y[lo]);
        const int x_lo = std::max(0, bx - 1), x_hi = std::min(nbx_ - 1, bx + 1);
        for (int yy = std::max(0, by - 1), r = 0; yy <= std::min(nby_ - 1, by + 1); ++yy, ++r) {
          const std::int64_t row = static_cast<std::int64_t>(yy) * nbx_;
          cand[r][0] = bucket_start_[row + x_lo];
          cand[r][1] = bucket_start_[row + x_hi + 1];
          any_candidate = any_candidate || cand[r][1] > cand[r][0];
        }
      }
      for (std::int64_t i = lo; i < hi; ++i) {
        const double m = q.weight[i] * cap;
        q.weight[i] = m;
        if (q.vx[i] * q.vx[i] + q.vy[i] * q.vy[i] < slow2) {
          // A particle at (almost) zero speed is the static hypothesis (occ and v = 0): its mass
          // votes static and the particle dies at resampling.
          slow_mass += m;
          q.w_position[i] = q.w_velocity[i] = q.weight[i] = 0.0;
          continue;
        }
        // Nearest detection within the cutoff (ties to the lower detection index).
        int jn = -1;
        double d2 = cutoff2;
        if (any_candidate) {
          const double px = q.x[i], py = q.y[i];
          for (const auto& range : cand) {
            for (std::int64_t k = range[0]; k < range[1]; ++k) {
              const double ex = det_x_[k] - px, ey = det_y_[k] - py;
              const double e2 = ex * ex + ey * ey;
              if (e2 < d2 || (e2 == d2 && jn >= 0 && bucket_items_[k] < jn)) {
                d2 = e2;
                jn = bucket_items_[k];
              }
            }
          }
        }
        double lp = keep, lv = keep;  // unobserved: decayed prior
        if (jn >= 0 || observed) {
          // Float exp: kernel values need no double precision and this runs per particle.
          const double fd = jn < 0 ? 0.0 : std::exp(static_cast<float>(-d2 * inv_2sf2));
          double fv = 0.0;
          if (jn >= 0) {
            const double ex = q.vx[i] - z[jn].radial_velocity.x();
            const double ey = q.vy[i] - z[jn].radial_velocity.y();
            fv = ExpUnder(static_cast<float>(-(ex * ex + ey * ey) * inv_2v2));
          }
          lp = fd * keep;                    // eq. (7)
          lv = fd * fv + (1.0 - fd) * keep;  // eq. (8), multiplicative blend
        }
        const double wp = lp * q.w_position[i], wv = lv * q.w_velocity[i];
        q.w_position[i] = wp;
        q.w_velocity[i] = wv;
        fast_mass += m;
        sum_pos += wp;
        sum_vel += wv;
        a_dyn += m * mode_factor(lp, lv);
      }
      // The static hypothesis is scored like a particle with v = 0 at the cell centre.
      double ls_pos = keep, ls_vel = keep;
      if (j >= 0 || observed) {
        const double fv0 = j >= 0 ? fv0_of[j] : 0.0;
        ls_pos = occ_k * keep;
        ls_vel = occ_k * fv0 + (1.0 - occ_k) * keep;
      }
      const double l_static = mode_factor(ls_pos, ls_vel);

      // --- Joint normalisation of the occupied mass (eqs. 9-12 on o_up). ---
      double a_static =
          (s_pred + slow_mass) * l_static + p.static_gain * p.occupied_mass * static_k;
      // No birth hypothesis from a detection no road object could produce (|v_r| > max_speed):
      // such returns are clutter; their occupied mass stays unassigned (unknown).
      const bool plausible = j < 0 || z[j].radial_velocity.squaredNorm() <= max_speed2;
      double a_birth = plausible ? p.birth_probability * occ_k * (1.0 - o_pred) : 0.0;
      if (a_static + a_dyn + a_birth <= 0.0) {
        // Every hypothesis got zero likelihood (e.g. position weights far from all detections):
        // the measurement cannot arbitrate, so the predicted split is kept.
        a_static = s_pred + slow_mass;
        a_dyn = fast_mass;
      }
      double q_norm = a_static + a_dyn + a_birth;
      // Subnormal likelihoods (e.g. a static mass decayed to 5e-324 and nothing else) lose their
      // precision in o_up * a / q_norm: the product rounds up to the smallest subnormal and the
      // share comes out as o_up * 1, breaking F + S <= 1 (found by the soak test,
      // docs/reliability.md). Scaling all three by 2^600 is exact and restores full precision;
      // normal values are untouched, so results elsewhere stay bit-identical.
      if (q_norm > 0.0 && q_norm < std::numeric_limits<double>::min()) {
        constexpr double kScale = 0x1p600;
        a_static *= kScale;
        a_dyn *= kScale;
        a_birth *= kScale;
        q_norm = a_static + a_dyn + a_birth;
      }
      double s_up = 0.0, rho_p = 0.0, rho_b = 0.0;
      if (q_norm > 0.0) {
        s_up = o_up * a_static / q_norm;
        rho_p = o_up * a_dyn / q_norm;
        rho_b = o_up * a_birth / q_norm;
      }

      // --- Normalise weights so that they sum to rho_p in the cell; w_resample by mode. ---
      double sum_res = 0.0;
      for (std::int64_t i = lo; i < hi; ++i) {
        if (q.weight[i] == 0.0) continue;
        const double m = q.weight[i];
        const double wp = sum_pos > 0.0 ? rho_p * q.w_position[i] / sum_pos : rho_p * m / fast_mass;
        const double wv = sum_vel > 0.0 ? rho_p * q.w_velocity[i] / sum_vel : rho_p * m / fast_mass;
        q.w_position[i] = wp;
        q.w_velocity[i] = wv;
        const double wr = mode_factor(wp, wv);  // w_resample
        q.weight[i] = wr;
        sum_res += wr;
      }
      if (sum_res > 0.0) {
        const double k = rho_p / sum_res;
        for (std::int64_t i = lo; i < hi; ++i) q.weight[i] = static_cast<float>(q.weight[i] * k);
      }
      free_[s] = f_up;
      static_[s] = s_up;
      // Reported dynamic mass: persistent particles only. New-born mass is occupied mass whose
      // motion no prediction has confirmed yet; counting it as dynamic would mark every new
      // detection with a Doppler (clutter included) dynamic at once. It stays in the unknown share
      // of the cell until its particles survive a cycle (docs/algorithm.md, step 5).
      dynamic_[s] = rho_p;
      born_[s] = rho_b;
      if (rho_b != 0.0) born_list[n_born++] = s;
    }
    born_count_[ch] = n_born;
  }
}

void DynamicGrid::Birth(std::span<const Measurement> z) {
  const std::int64_t nb = static_cast<std::int64_t>(births_.size());
  const std::int64_t nc = num_cells_;
  // Prefix sums of the birth masses with the summation order of ExclusiveScan (blocks of
  // kScanBlock), without materialising them: block totals here, running sums in the loop below.
  const std::int64_t blocks = (nc + kScanBlock - 1) / kScanBlock;
  std::vector<double>& tot = born_block_;
  tot.resize(blocks + 1);
  // Most cells have no birth mass; adding +-0 leaves acc (>= +0) unchanged, so only the cells of
  // UpdateCells' per-chunk lists (non-zero mass, in cell order) are visited: same sums.
  const std::int64_t n_chunks = static_cast<std::int64_t>(born_count_.size());
  constexpr std::int64_t kChunksPerBlock = kScanBlock / kCellChunk;
  const auto for_each_born = [&](std::int64_t b, auto&& f) {
    for (std::int64_t ch = b * kChunksPerBlock; ch < std::min(n_chunks, (b + 1) * kChunksPerBlock);
         ++ch) {
      const std::int64_t* list = born_cells_.data() + ch * kCellChunk;
      for (std::int32_t t = 0; t < born_count_[ch]; ++t) f(list[t]);
    }
  };
#pragma omp parallel for schedule(static) if (blocks > 8)
  for (std::int64_t b = 0; b < blocks; ++b) {
    double acc = 0.0;
    for_each_born(b, [&](std::int64_t s) { acc += born_[s]; });
    tot[b + 1] = acc;
  }
  tot[0] = 0.0;
  for (std::int64_t b = 0; b < blocks; ++b) tot[b + 1] += tot[b];
  const double total = tot[blocks];
  if (nb == 0) return;
  if (!(total > 0.0)) {
    std::fill(births_.weight.begin(), births_.weight.end(), 0.0);
    std::fill(births_.w_position.begin(), births_.w_position.end(), 0.0);
    std::fill(births_.w_velocity.begin(), births_.w_velocity.end(), 0.0);
    return;
  }
  // New-born particles are spread over cells in proportion to their birth mass (systematic
  // allocation, SystematicRanges); every birth carries the same mass total / num_birth.
  CounterRng offset_rng(seed_, RngPurpose::kFilterBirth, step_, 0xFFFFFFFFu);
  const double u = offset_rng.Uniform();
  const double scale = static_cast<double>(nb) / total;
  const double mass = total / static_cast<double>(nb);
  const double r = params_.resolution;
  const double vmax = params_.birth_max_tangential_speed;
  const auto start = [&](std::int64_t i, double cumulative) -> std::int64_t {
    if (i == 0) return 0;
    if (i == nc) return nb;
    return std::clamp(CeilToInt(cumulative * scale - u), std::int64_t{0}, nb);
  };
  // Running sum at each chunk start (sequential from the block base, as in the loop below), so
  // that the births can be generated chunk by chunk (load balance: births cluster in few blocks).
  double* const chunk_acc = born_chunk_acc_.data();
#pragma omp parallel for schedule(static) if (blocks > 8)
  for (std::int64_t b = 0; b < blocks; ++b) {
    double acc = tot[b];
    for (std::int64_t ch = b * kChunksPerBlock; ch < std::min(n_chunks, (b + 1) * kChunksPerBlock);
         ++ch) {
      chunk_acc[ch] = acc;
      const std::int64_t* list = born_cells_.data() + ch * kCellChunk;
      for (std::int32_t t = 0; t < born_count_[ch]; ++t) acc += born_[list[t]];
    }
  }
#pragma omp parallel for schedule(dynamic, 1)
  for (std::int64_t ch = 0; ch < n_chunks; ++ch) {
    const std::int64_t b = ch / kChunksPerBlock;
    const std::int64_t last = std::min(nc, (b + 1) * kScanBlock) - 1;
    const bool has_last = last < (ch + 1) * kCellChunk;  // the block's last cell is in this chunk
    double acc = chunk_acc[ch];
    bool last_seen = false;
    // Inside a block a zero mass leaves the running sum unchanged: empty range. Only the cells
    // with mass and the block's last cell (where the block total takes over) can get births.
    const auto visit = [&](std::int64_t s, double born) {
      const bool block_end = s == last;
      last_seen = last_seen || block_end;
      const double cum_s = acc;
      if (born != 0.0) acc += born;
      const std::int64_t k_lo = start(s, cum_s), k_hi = start(s + 1, block_end ? tot[b + 1] : acc);
      if (k_lo == k_hi) return;
      GenerateBirths(z, s, k_lo, k_hi, mass, r, vmax);
    };
    const std::int64_t* list = born_cells_.data() + ch * kCellChunk;
    for (std::int32_t t = 0; t < born_count_[ch]; ++t) visit(list[t], born_[list[t]]);
    if (has_last && !last_seen) visit(last, 0.0);
  }
}

void DynamicGrid::GenerateBirths(std::span<const Measurement> z, std::int64_t s, std::int64_t k_lo,
                                 std::int64_t k_hi, double mass, double r, double vmax) {
  const int j = near_det_[s];
  // Global cell of storage index s: the unique one inside the current window.
  const std::int64_t sx = s % nx_, sy = s / nx_;
  const std::int64_t gx = origin_gx_ + Mod(sx - origin_gx_, nx_);
  const std::int64_t gy = origin_gy_ + Mod(sy - origin_gy_, ny_);
  if (j < 0) {
    // Birth mass needs a detection nearby; only a rounding jump of the prefix sums at a block
    // boundary could land here. Keep the slots harmless (zero mass at the cell centre).
    for (std::int64_t k = k_lo; k < k_hi; ++k) {
      births_.x[k] = (static_cast<double>(gx) + 0.5) * r;
      births_.y[k] = (static_cast<double>(gy) + 0.5) * r;
      births_.vx[k] = births_.vy[k] = 0.0f;
      births_.weight[k] = births_.w_position[k] = births_.w_velocity[k] = 0.0f;
    }
    return;
  }
  const Measurement& m = z[j];
  Vector2 los = m.position - m.sensor_position;
  const double los_n = los.norm();
  los = los_n > 0.0 ? Vector2(los / los_n) : Vector2(1.0, 0.0);
  const Vector2 tangent(-los.y(), los.x());
  const double v_radial = m.radial_velocity.dot(los);  // signed compensated radial speed
  const double vt_max = std::min(
      vmax, std::sqrt(std::max(0.0, params_.max_speed * params_.max_speed - v_radial * v_radial)));
  constexpr std::int64_t kBatch = 64;
  alignas(64) std::uint32_t raw[4][kBatch], raw2[4][kBatch];
  for (std::int64_t k0 = k_lo; k0 < k_hi; k0 += kBatch) {
    const std::int64_t cnt = std::min(kBatch, k_hi - k0);
    // Draws 0-3 (block 0) and 4 (block 1) of CounterRng(seed, kFilterBirth, step, k).
    detail::PhiloxBlocks(seed_, RngPurpose::kFilterBirth, step_, static_cast<std::uint32_t>(k0),
                         cnt, 0, raw[0], raw[1], raw[2], raw[3]);
    detail::PhiloxBlocks(seed_, RngPurpose::kFilterBirth, step_, static_cast<std::uint32_t>(k0),
                         cnt, 1, raw2[0], raw2[1], raw2[2], raw2[3]);
    for (std::int64_t t = 0; t < cnt; ++t) {
      const std::int64_t k = k0 + t;
      births_.x[k] = (static_cast<double>(gx) + detail::ToUnit24(raw[0][t])) * r;
      births_.y[k] = (static_cast<double>(gy) + detail::ToUnit24(raw[1][t])) * r;
      float n0, n1;
      detail::Normal2FromRaw(raw[2][t], raw[3][t], &n0, &n1);
      // Radial component from the Doppler, tangential one unobservable: sampled uniformly, within
      // what keeps the speed at most max_speed.
      const Vector2 v = (v_radial + params_.birth_sigma_radial * n0) * los +
                        vt_max * (2.0 * detail::ToUnit24(raw2[0][t]) - 1.0) * tangent;
      births_.vx[k] = v.x();
      births_.vy[k] = v.y();
      births_.weight[k] = births_.w_position[k] = births_.w_velocity[k] = mass;
    }
  }
}

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
#pragma omp parallel for schedule(static)
    for (std::int64_t k = 0; k < n; ++k) {
      const std::int64_t i = k * n_src / n;
      if (i < n_in) {
        particles_.CopyFrom(sorted_, i, k);
      } else {
        particles_.CopyFrom(births_, i - n_in, k);
      }
      particles_.weight[k] = particles_.w_position[k] = particles_.w_velocity[k] = 0.0;
    }
    return;
  }
  CounterRng rng(seed_, RngPurpose::kFilterResample, step_, 0);
  // Systematic ranges (SystematicRanges) computed inside the copy loop: source i owns output
  // slots [start(i), start(i + 1)).
  const double u = rng.Uniform();
  const double scale = static_cast<double>(n) / total;
  const double share = total / static_cast<double>(n);
  const double* const cum = scan_out_.data();
#pragma omp parallel
  {
    // Contiguous source ranges per thread; each range boundary is computed once.
    const std::int64_t nt = omp_get_num_threads(), t = omp_get_thread_num();
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
  }
}

void DynamicGrid::Update(const EgoInput& ego, std::span<const Measurement> measurements,
                         std::span<const SensorCoverage> coverage, double dt) {
  if (!(dt >= 0.0) || !std::isfinite(dt)) {
    throw std::invalid_argument("DynamicGrid::Update: dt must be finite and >= 0, got " +
                                std::to_string(dt));
  }
  if (!ego.pose.position.allFinite()) {
    throw std::invalid_argument("DynamicGrid::Update: ego position is not finite");
  }
  for (const SensorCoverage& c : coverage) {
    if (!c.origin.allFinite() || !std::isfinite(c.boresight) || !(c.half_fov >= 0.0) ||
        !(c.min_range >= 0.0) || !(c.max_range >= c.min_range) || !std::isfinite(c.max_range)) {
      throw std::invalid_argument(
          "DynamicGrid::Update: SensorCoverage needs a finite origin/boresight, half_fov >= 0 "
          "and 0 <= min_range <= max_range < inf");
    }
  }
  if (!initialized_) {
    Initialize(ego);
  } else {
    ShiftTo(ego.pose.position);  // 1. ego motion: whole cells
  }
  PredictAndSort(dt);                            // 2. prediction, 3. assignment
  BuildMeasurementGrid(measurements, coverage);  // 4. measurement grid
  UpdateCells(measurements);                     // 5.-6. occupancy update, weights, 9. statistics
  Birth(measurements);                           // 7. birth
  Resample();                                    // 8. resampling
  ++step_;
}

std::optional<std::string> DynamicGrid::CheckInvariants() const {
  constexpr double kEps = 1e-9;
  double dynamic_total = 0.0;
  for (std::int64_t i = 0; i < num_cells_; ++i) {
    const double f = free_[i], st = static_[i], d = dynamic_[i];
    if (!(std::isfinite(f) && std::isfinite(st) && std::isfinite(d)) || f < -kEps || st < -kEps ||
        d < -kEps || f + st + d > 1.0 + 1e-6)
      return "cell " + std::to_string(i) + ": masses free " + std::to_string(f) + ", static " +
             std::to_string(st) + ", dynamic " + std::to_string(d) + " break 0 <= m, sum <= 1";
    dynamic_total += d + born_[i];
  }
  if (static_cast<int>(particles_.size()) != params_.num_particles)
    return "particle count " + std::to_string(particles_.size()) + " != num_particles " +
           std::to_string(params_.num_particles);
  double weight_total = 0.0;
  for (std::size_t i = 0; i < particles_.size(); ++i) {
    const double values[] = {
        particles_.x[i],          particles_.y[i],          particles_.vx[i],    particles_.vy[i],
        particles_.w_position[i], particles_.w_velocity[i], particles_.weight[i]};
    for (double v : values)
      if (!std::isfinite(v)) return "particle " + std::to_string(i) + " has a non-finite state";
    if (particles_.weight[i] < 0.0 || particles_.w_position[i] < 0.0 ||
        particles_.w_velocity[i] < 0.0)
      return "particle " + std::to_string(i) + " has a negative weight";
    weight_total += particles_.weight[i];
  }
  // Resampling carries the persistent and the new-born mass; new-born mass of cells that got no
  // birth particle (systematic allocation) is dropped, so the particles never hold more.
  if (weight_total > dynamic_total * (1.0 + 1e-5) + 1e-6)
    return "particle weights sum to " + std::to_string(weight_total) +
           ", more than the cells' dynamic and new-born mass " + std::to_string(dynamic_total);
  return std::nullopt;
}

}  // namespace dualgrid::filter
