#include "dualgrid/filter/dynamic_grid.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include <omp.h>

#include "dualgrid/core/random.hpp"
#include "grid_internal.hpp"

namespace dualgrid::filter {

using namespace detail;

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

void DynamicGrid::ExportMasses(std::span<float> free, std::span<float> static_occ,
                               std::span<float> dynamic, std::span<std::uint8_t> observed) const {
  const std::size_t n = static_cast<std::size_t>(nx_) * static_cast<std::size_t>(ny_);
  if (free.size() != n || static_occ.size() != n || dynamic.size() != n || observed.size() != n)
    throw std::invalid_argument(
        "DynamicGrid::ExportMasses: spans of " + std::to_string(free.size()) + "/" +
        std::to_string(static_occ.size()) + "/" + std::to_string(dynamic.size()) + "/" +
        std::to_string(observed.size()) + " entries for " + std::to_string(n) + " cells");
  for (int y = 0; y < ny_; ++y) {
    const std::int64_t row = Mod(origin_gy_ + y, ny_) * nx_;
    std::int64_t sx = Mod(origin_gx_, nx_);  // walks the circular row, wrapping once
    std::size_t i = static_cast<std::size_t>(y) * static_cast<std::size_t>(nx_);
    for (int x = 0; x < nx_; ++x, ++i) {
      const std::int64_t s = row + sx;
      free[i] = static_cast<float>(free_[s]);
      static_occ[i] = static_cast<float>(static_[s]);
      dynamic[i] = static_cast<float>(dynamic_[s]);
      observed[i] = (view_[s] & kObserved) != 0 ? 1 : 0;
      if (++sx == nx_) sx = 0;
    }
  }
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
