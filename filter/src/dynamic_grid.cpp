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

// atan2 with |error| < 1e-5 rad: bearing bins are ~1e-2 rad wide, and std::atan2 per cell and
// sensor dominated the free-space pass.
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
  hist_total_.assign(c + 1, 0);
  hist_.assign(static_cast<std::size_t>(kMaxSortChunks) * (c + 1), 0);
  scan_in_.assign(n + b, 0.0);
  scan_out_.assign(n + b + 1, 0.0);
  ranges_.assign(n + b + 1, 0);
  born_scan_.assign(c + 1, 0.0);
  born_ranges_.assign(c + 1, 0);
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

void DynamicGrid::SortParticles() {
  const std::int64_t n = static_cast<std::int64_t>(particles_.size());
  const std::int64_t c1 = num_cells_ + 1;  // bucket num_cells_ collects particles off the grid
  const double inv_r = 1.0 / params_.resolution;
  const std::int64_t sx0 = Mod(origin_gx_, nx_), sy0 = Mod(origin_gy_, ny_);
#pragma omp parallel for schedule(static)
  for (std::int64_t i = 0; i < n; ++i) {
    const double fx = std::floor(particles_.x[i] * inv_r) - static_cast<double>(origin_gx_);
    const double fy = std::floor(particles_.y[i] * inv_r) - static_cast<double>(origin_gy_);
    const bool inside = fx >= 0.0 && fy >= 0.0 && fx < nx_ && fy < ny_;  // false for NaN too
    if (!inside) {
      cell_of_[i] = num_cells_;
      continue;
    }
    // Storage index without integer division (hot loop): wrap once.
    std::int64_t sx = sx0 + static_cast<std::int64_t>(fx), sy = sy0 + static_cast<std::int64_t>(fy);
    if (sx >= nx_) sx -= nx_;
    if (sy >= ny_) sy -= ny_;
    cell_of_[i] = sy * nx_ + sx;
  }
  const int chunks = std::clamp(omp_get_max_threads(), 1, kMaxSortChunks);
  // Counting sort, stable: particle order within a cell = order before sorting, for any chunking.
#pragma omp parallel for schedule(static)
  for (int k = 0; k < chunks; ++k) {
    std::int32_t* h = hist_.data() + k * c1;
    std::fill_n(h, c1, 0);
    for (std::int64_t i = k * n / chunks; i < (k + 1) * n / chunks; ++i) ++h[cell_of_[i]];
  }
#pragma omp parallel for schedule(static)
  for (std::int64_t c = 0; c < c1; ++c) {
    std::int64_t t = 0;
    for (int k = 0; k < chunks; ++k) t += hist_[k * c1 + c];
    hist_total_[c] = t;
  }
  ExclusiveScan(std::span<const std::int64_t>(hist_total_.data(), c1),
                std::span<std::int64_t>(cell_start_.data(), c1 + 1));
#pragma omp parallel for schedule(static)
  for (std::int64_t c = 0; c < c1; ++c) {
    std::int64_t run = cell_start_[c];
    for (int k = 0; k < chunks; ++k) {
      const std::int64_t t = hist_[k * c1 + c];
      hist_[k * c1 + c] = static_cast<std::int32_t>(run);
      run += t;
    }
  }
#pragma omp parallel for schedule(static)
  for (int k = 0; k < chunks; ++k) {
    std::int32_t* h = hist_.data() + k * c1;
    for (std::int64_t i = k * n / chunks; i < (k + 1) * n / chunks; ++i) {
      sorted_.CopyFrom(particles_, i, h[cell_of_[i]]++);
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
#pragma omp parallel for schedule(static)
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
      const double cb = std::cos(sc.boresight), sb = std::sin(sc.boresight);
      const bool narrow = sc.half_fov < 0.5 * kPi;
      const double tan_hf = narrow ? std::tan(sc.half_fov) : 0.0;
      const double min2 = sc.min_range * sc.min_range, max2 = sc.max_range * sc.max_range;
      const double* bins = bin_range_.data() + bin_offset_[k];
      const int nbins = static_cast<int>(bin_offset_[k + 1] - bin_offset_[k]);
      const double inv_bin = 1.0 / params_.free_angle_bin;
      for (int lx = lx_lo; lx <= lx_hi; ++lx) {
        const double dx = x0 + (lx + 0.5) * r - sc.origin.x();
        const double d2 = dx * dx + dy * dy;
        if (d2 < min2 || d2 > max2) continue;
        const double fx = dx * cb + dy * sb, fy = dy * cb - dx * sb;
        if (narrow && (fx <= 0.0 || std::abs(fy) > fx * tan_hf)) continue;
        const double rel = FastAtan2(fy, fx);
        if (std::abs(rel) > sc.half_fov) continue;
        const std::int64_t sx = sx0 + lx;
        const std::int64_t s = row + (sx >= nx_ ? sx - nx_ : sx);
        const int b = std::clamp(static_cast<int>((rel + sc.half_fov) * inv_bin), 0, nbins - 1);
        const double br = bins[b];
        // Branch-free: free in front of the bin's closest detection, unknown behind it; a bin
        // without any detection is weakly free over the whole range.
        view_[s] |= static_cast<std::uint8_t>(kObserved | (br == kInf ? kNoReturn : 0) |
                                              (br != kInf && d2 < br * br ? kFreeRay : 0));
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
  const double cutoff = p.cutoff_sigmas * p.sigma_f, cutoff2 = cutoff * cutoff;
  ParticleSet& q = sorted_;
  // Cells in parallel; dynamic scheduling only balances load, every value is computed by one
  // thread from the same inputs, so results do not depend on the thread count.
#pragma omp parallel for schedule(dynamic, 512)
  for (std::int64_t s = 0; s < num_cells_; ++s) {
    const std::int64_t lo = cell_start_[s], hi = cell_start_[s + 1];
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
      static_k = std::exp(-0.5 * (d2 * inv_sd2 + z[j].radial_velocity.squaredNorm() * inv_sv2));
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
    if (hi == lo && j < 0) {
      // Fast path (most cells): no particle, no detection. The general equations reduce to a
      // free/static Dempster update with the whole occupied mass static and no dynamic mass.
      const double norm0 = 1.0 / (1.0 - s_pred * z_free);
      free_[s] = (f_pred + u_pred * z_free) * norm0;
      static_[s] = s_pred * (1.0 - z_free) * norm0;
      dynamic_[s] = 0.0;
      born_[s] = 0.0;
      continue;
    }

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
          fv = std::exp(static_cast<float>(-(ex * ex + ey * ey) * inv_2v2));
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
      const double fv0 = j >= 0 ? std::exp(-z[j].radial_velocity.squaredNorm() * inv_2v2) : 0.0;
      ls_pos = occ_k * keep;
      ls_vel = occ_k * fv0 + (1.0 - occ_k) * keep;
    }
    const double l_static = mode_factor(ls_pos, ls_vel);

    // --- Joint normalisation of the occupied mass (eqs. 9-12 on o_up). ---
    double a_static = (s_pred + slow_mass) * l_static + p.static_gain * p.occupied_mass * static_k;
    const double a_birth = p.birth_probability * occ_k * (1.0 - o_pred);
    if (a_static + a_dyn + a_birth <= 0.0) {
      // Every hypothesis got zero likelihood (e.g. position weights far from all detections):
      // the measurement cannot arbitrate, so the predicted split is kept.
      a_static = s_pred + slow_mass;
      a_dyn = fast_mass;
    }
    const double q_norm = a_static + a_dyn + a_birth;
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
    // Reported dynamic mass: persistent particles only. New-born mass is occupied mass whose motion
    // no prediction has confirmed yet; counting it as dynamic would mark every new detection with
    // a Doppler (clutter included) dynamic at once. It stays in the unknown share of the cell
    // until its particles survive a cycle (docs/algorithm.md, step 5).
    dynamic_[s] = rho_p;
    born_[s] = rho_b;
  }
}

void DynamicGrid::Birth(std::span<const Measurement> z) {
  const std::int64_t nb = static_cast<std::int64_t>(births_.size());
  ExclusiveScan(std::span<const double>(born_.data(), num_cells_),
                std::span<double>(born_scan_.data(), num_cells_ + 1));
  const double total = born_scan_[num_cells_];
  if (nb == 0) return;
  if (!(total > 0.0)) {
    std::fill(births_.weight.begin(), births_.weight.end(), 0.0);
    std::fill(births_.w_position.begin(), births_.w_position.end(), 0.0);
    std::fill(births_.w_velocity.begin(), births_.w_velocity.end(), 0.0);
    return;
  }
  // New-born particles are spread over cells in proportion to their birth mass (systematic
  // allocation); every birth carries the same mass total / num_birth.
  CounterRng offset_rng(seed_, RngPurpose::kFilterBirth, step_, 0xFFFFFFFFu);
  SystematicRanges(std::span<const double>(born_scan_.data(), num_cells_ + 1),
                   static_cast<std::size_t>(nb), offset_rng.Uniform(),
                   std::span<std::int64_t>(born_ranges_.data(), num_cells_ + 1));
  const double mass = total / static_cast<double>(nb);
  const double r = params_.resolution;
  const double vmax = params_.birth_max_tangential_speed;
#pragma omp parallel for schedule(static)
  for (std::int64_t s = 0; s < num_cells_; ++s) {
    if (born_ranges_[s] == born_ranges_[s + 1]) continue;
    const int j = near_det_[s];
    assert(j >= 0);  // birth mass needs a detection nearby
    const Measurement& m = z[j];
    Vector2 los = m.position - m.sensor_position;
    const double los_n = los.norm();
    los = los_n > 0.0 ? Vector2(los / los_n) : Vector2(1.0, 0.0);
    const Vector2 tangent(-los.y(), los.x());
    const double v_radial = m.radial_velocity.dot(los);  // signed compensated radial speed
    // Global cell of storage index s: the unique one inside the current window.
    const std::int64_t sx = s % nx_, sy = s / nx_;
    const std::int64_t gx = origin_gx_ + Mod(sx - origin_gx_, nx_);
    const std::int64_t gy = origin_gy_ + Mod(sy - origin_gy_, ny_);
    for (std::int64_t k = born_ranges_[s]; k < born_ranges_[s + 1]; ++k) {
      CounterRng rng(seed_, RngPurpose::kFilterBirth, step_, static_cast<std::uint32_t>(k));
      births_.x[k] = (static_cast<double>(gx) + detail::Uniform24(rng)) * r;
      births_.y[k] = (static_cast<double>(gy) + detail::Uniform24(rng)) * r;
      float n0, n1;
      detail::Normal2(rng, &n0, &n1);
      // Radial component from the Doppler, tangential one unobservable: sampled uniformly.
      const Vector2 v = (v_radial + params_.birth_sigma_radial * n0) * los +
                        vmax * (2.0 * detail::Uniform24(rng) - 1.0) * tangent;
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
  const auto src_weight = [&](std::int64_t i) {
    return i < n_in ? sorted_.weight[i] : births_.weight[i - n_in];
  };
#pragma omp parallel for schedule(static)
  for (std::int64_t i = 0; i < n_src; ++i) scan_in_[i] = src_weight(i);
  ExclusiveScan(std::span<const double>(scan_in_.data(), n_src),
                std::span<double>(scan_out_.data(), n_src + 1));
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
  SystematicRanges(std::span<const double>(scan_out_.data(), n_src + 1),
                   static_cast<std::size_t>(n), rng.Uniform(),
                   std::span<std::int64_t>(ranges_.data(), n_src + 1));
  const double share = total / static_cast<double>(n);
#pragma omp parallel for schedule(static)
  for (std::int64_t i = 0; i < n_src; ++i) {
    if (ranges_[i] == ranges_[i + 1]) continue;
    const ParticleSet& src = i < n_in ? sorted_ : births_;
    const std::int64_t si = i < n_in ? i : i - n_in;
    // Copies carry the new equal share; w_position / w_velocity keep their ratio to the weight.
    const double ratio = share / src.weight[si];
    for (std::int64_t k = ranges_[i]; k < ranges_[i + 1]; ++k) {
      particles_.CopyFrom(src, si, k);
      particles_.weight[k] = share;
      particles_.w_position[k] *= ratio;
      particles_.w_velocity[k] *= ratio;
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
  PredictParticles(particles_, dt, params_.process_noise_position, params_.process_noise_velocity,
                   params_.persistence, seed_, step_);  // 2. prediction
  SortParticles();                                      // 3. assignment
  BuildMeasurementGrid(measurements, coverage);         // 4. measurement grid
  UpdateCells(measurements);  // 5.-6. occupancy update, weights, 9. statistics
  Birth(measurements);        // 7. birth
  Resample();                 // 8. resampling
  ++step_;
}

}  // namespace dualgrid::filter
