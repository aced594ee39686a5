// The cycle's driver (DynamicGrid::Update, docs/algorithm.md "One cycle"), construction, geometry
// accessors and the invariant check; each stage of the cycle has its own file:
// ego_shift.cpp (1), predict_sort.cpp (2-3), measurement_grid.cpp (4, eqs. 2-4),
// update_cells.cpp (5-6, eqs. 7-12, 14), birth.cpp (7), resample.cpp (8), cell_moments.cpp (9).
#include "dualgrid/filter/dynamic_grid.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "dualgrid/core/parallel.hpp"
#include "dualgrid/core/random.hpp"
#include "grid_internal.hpp"
#include "team.hpp"

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
  const auto n = static_cast<std::size_t>(params_.num_particles);
  const auto b = static_cast<std::size_t>(params_.num_birth);
  particles_.resize(n);
  sorted_.resize(n);
  births_.resize(b);
  birth_draw_.assign(6 * b, 0.0f);
  cell_of_.assign(n, 0);
  cell_start_.assign(c + 2, 0);
  born_cells_.assign(c, 0);
  born_count_.assign(static_cast<std::size_t>((num_cells_ + kCellChunk - 1) / kCellChunk), 0);
  born_chunk_acc_.assign(born_count_.size(), 0.0);
  hist_total_.assign(static_cast<std::size_t>(num_cells_ / (1 << 10) + 2), 0);
  hist_.assign(static_cast<std::size_t>(kMaxSortChunks) * (c + 1), 0);
  scan_out_.assign(n + b + 1, 0.0);
  resample_owner_.assign(n, 0);
  scan_base_.assign(static_cast<std::size_t>((n + b + kScanBlock - 1) / kScanBlock + 1), 0.0);
  born_block_.assign(static_cast<std::size_t>((num_cells_ + kScanBlock - 1) / kScanBlock + 1), 0.0);
}

std::int64_t DynamicGrid::Storage(std::int64_t gx, std::int64_t gy) const {
  return Mod(gy, ny_) * nx_ + Mod(gx, nx_);
}

std::array<std::int64_t, 2> DynamicGrid::StorageOrigin() const {
  return {Mod(origin_gx_, nx_), Mod(origin_gy_, ny_)};
}

Position DynamicGrid::CellCenter(CellIndex c) const {
  const double r = params_.resolution;
  return {(static_cast<double>(origin_gx_ + c.x) + 0.5) * r,
          (static_cast<double>(origin_gy_ + c.y) + 0.5) * r};
}

void DynamicGrid::Update(const EgoInput& ego, std::span<const Measurement> measurements,
                         std::span<const SensorCoverage> coverage, double dt) {
  if (!own_measurement_) own_measurement_.emplace(params_);
  // Prepare refuses a non-finite centre or coverage before anything changes; the tables are
  // filled in the cycle's region (4. measurement grid, MeasurementGrid::Fill).
  own_measurement_->Prepare(ego.pose.position, measurements, coverage);
  Run(ego, *own_measurement_, dt, nullptr, &*own_measurement_, coverage);
}

void DynamicGrid::Update(const EgoInput& ego, const MeasurementGrid& measurement, double dt,
                         const PredictionNoise* noise) {
  Run(ego, measurement, dt, noise, nullptr, {});
}

void DynamicGrid::Run(const EgoInput& ego, const MeasurementGrid& measurement, double dt,
                      const PredictionNoise* noise, MeasurementGrid* fill,
                      std::span<const SensorCoverage> coverage) {
  if (!(dt >= 0.0) || !std::isfinite(dt)) {
    throw std::invalid_argument("DynamicGrid::Update: dt must be finite and >= 0, got " +
                                std::to_string(dt));
  }
  if (!(ego.pose.position.cwiseAbs().maxCoeff() <= FilterParams::kMaxCentre)) {  // also NaN
    throw std::invalid_argument(
        "DynamicGrid::Update: the ego position must be finite with |x|, |y| <= 1e9 m");
  }
  if (!measurement.SharesGeometry(params_) || (fill == nullptr && measurement.builds() == 0) ||
      measurement.origin_index() != OriginFor(ego.pose.position)) {
    throw std::invalid_argument(
        "DynamicGrid::Update: the MeasurementGrid was not built for this grid (another geometry, "
        "never built, or built for another ego position)");
  }
  if (noise != nullptr && !noise->Holds(seed_, step_, params_.num_particles)) {
    throw std::invalid_argument(
        "DynamicGrid::Update: the PredictionNoise holds another seed, step or fewer particles "
        "than this grid's next cycle (seed " +
        std::to_string(seed_) + ", step " + std::to_string(step_) + ", " +
        std::to_string(params_.num_particles) + " particles)");
  }
  const bool first = !initialized_;
  if (first) {
    InitializeOrigin(ego);  // the particles: in the cycle (SpreadParticles)
  } else {
    ShiftTo(ego.pose.position);  // 1. ego motion: whole cells
  }
  InvalidateExports();
  mg_ = &measurement;
  const std::span<const Measurement> z = measurement.measurements();
  cycle_params_ = ForCycle(params_, dt);  // per-cycle factors for this dt
  PrepareCycle(z.size());
  sorted_gx_ = origin_gx_;  // the cells the particles are sorted on below
  sorted_gy_ = origin_gy_;
  const auto cycle = [&](const Team& t) {
    // 4. measurement grid, 4a. Doppler fit. Fill ends without a barrier: the cycle reads its
    // tables only after the prediction's and the sort's first barriers (PredictAndSort).
    if (fill != nullptr) fill->Fill(t, coverage);
    Cycle(t, z, dt, noise, first);
  };
  if (OneThreadHere()) {  // no team to build (dualgrid/core/parallel.hpp)
    cycle(Team::Solo());
  } else {
#pragma omp parallel
    cycle(Team::OfRegion());
  }
  shift_gx_ = shift_gy_ = 0;  // applied in the prediction
  sorted_current_ = true;     // sorted_ and cell_start_ bin the particles on the current cells
  mg_ = nullptr;
  ++step_;
}

void DynamicGrid::PrepareCycle(std::size_t detections) {
  const std::size_t rows = std::max<std::size_t>(detections, 1);  // WeighTables reads row 0
  if (det_f_.size() < 9 * rows) det_f_.assign(9 * rows, 0.0f);    // grow only
  if (det_fv0_.size() < detections) det_fv0_.resize(detections);
  if (det_fit_k_.size() < detections) det_fit_k_.resize(detections);
  candidates_.Configure(nx_, ny_, params_.resolution, params_.cutoff_sigmas * params_.sigma_f,
                        detections);
}

void DynamicGrid::Cycle(const Team& t, std::span<const Measurement> z, double dt,
                        const PredictionNoise* noise, bool first) {
  if (first) SpreadParticles(t);
  PredictAndSort(t, z, dt, noise);  // 2. prediction, 3. assignment
  // 4. measurement grid and 4a. Doppler fit: in `measurement` (MeasurementGrid::Build).
  UpdateCells(t, z);  // 5.-6. occupancy update, weights, 9. statistics
  // 7. birth, with the resampling's prefix sums over the persistent particles beside it.
  BirthSums sums;  // this thread's own
  const bool births = BirthMass(t, sums);
  SingleNoWait(t, [&] { ScanPersistent(); });
  if (births) {
    DrawBirths(t, z, sums);
  } else {
    Barrier(t);
  }
  Resample(t);  // 8. resampling
}

namespace {

// The first n particles of `in` (grid-local, origin (gx, gy)) in the caller's frame.
void ExportParticles(const LocalParticles& in, std::size_t n, std::int64_t gx, std::int64_t gy,
                     double r, ParticleSet& out) {
  out.resize(n);
  const double x0 = static_cast<double>(gx) * r, y0 = static_cast<double>(gy) * r;
  for (std::size_t i = 0; i < n; ++i) {
    out.x[i] = x0 + in.x[i];
    out.y[i] = y0 + in.y[i];
  }
  std::copy_n(in.vx.begin(), n, out.vx.begin());
  std::copy_n(in.vy.begin(), n, out.vy.begin());
  std::copy_n(in.w_position.begin(), n, out.w_position.begin());
  std::copy_n(in.w_velocity.begin(), n, out.w_velocity.begin());
  std::copy_n(in.weight.begin(), n, out.weight.begin());
}

}  // namespace

const ParticleSet& DynamicGrid::ExportOnce(Exported& out, const LocalParticles& in, std::int64_t gx,
                                           std::int64_t gy) const {
  const std::lock_guard<std::mutex> lock(export_lock_.m);
  if (!out.valid) {
    ExportParticles(in, in.size(), gx, gy, params_.resolution, out.set);
    out.valid = true;
  }
  return out.set;
}

const ParticleSet& DynamicGrid::particles() const {
  return ExportOnce(exported_, particles_, origin_gx_, origin_gy_);
}

// All of sorted_ (as before the float state): entries past num_weighted_particles() are stale but
// sized like the set.
const ParticleSet& DynamicGrid::weighted_particles() const {
  return ExportOnce(exported_weighted_, sorted_, sorted_gx_, sorted_gy_);
}

double DynamicGrid::NewbornMass() const {
  double total = 0.0;
  for (const double b : born_) total += b;
  return total;
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
