// Radar-only dynamic occupancy grid with position, velocity and dual particle weights
// (Ronecker, Stolz, Watzenig 2023) on a Nuss-style random-finite-set particle grid.
// Pipeline and choices: docs/algorithm.md.
//
// Frame: the filter is frame-agnostic. Every input and output is in one Cartesian frame, the
// caller's (in dualgrid the grid frame, docs/algorithm.md "Grid frame"), and the grid's cells are
// axis-aligned with it.
#pragma once

#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <mutex>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "dualgrid/core/types.hpp"
#include "dualgrid/filter/local_particles.hpp"
#include "dualgrid/filter/measurement_grid.hpp"
#include "dualgrid/filter/params.hpp"
#include "dualgrid/filter/particles.hpp"
#include "dualgrid/filter/prediction_noise.hpp"
#include "dualgrid/filter/weigh_particles.hpp"

namespace dualgrid::filter {

namespace detail {
struct Team;
}  // namespace detail

/// The ego in the caller's frame; the grid is centred on pose.position (a caller wanting the ego
/// elsewhere in the grid offsets it, as dualgrid's filter.ahead / filter.left do).
struct EgoInput {
  Pose2 pose;
  Velocity velocity = Velocity::Zero();
};

/// Logical cell index: x along the frame's +x, y along its +y, 0..cells-1, independent of storage.
struct CellIndex {
  int x = 0;
  int y = 0;
};

/// Masses of one cell after the last Update; free + static_occ + dynamic + unknown = 1.
struct CellState {
  double free = 0.0;
  double static_occ = 0.0;
  double dynamic = 0.0;
  double unknown = 1.0;
  /// Weighted mean and covariance of the persistent moving particles of the cell after the
  /// weight update (before resampling); zero when the cell has none.
  Velocity mean_velocity = Velocity::Zero();
  Matrix2 velocity_cov = Matrix2::Zero();
  /// Inside the field of view of at least one sensor this cycle.
  bool observed = false;
};

/// The keep callable of DynamicGrid::ForEachWeightedCellWhere for byte layers (e.g. eval::CellClass
/// bytes) that keeps the cells holding `value`: the same cells in the same order as any callable
/// returning v == value, but the scan tests 8 cells per 64-bit word and skips words holding none.
struct ByteIs {
  std::uint8_t value = 0;
  bool operator()(std::uint8_t v) const { return v == value; }
};

/// One weighted particle in the caller's frame (DynamicGrid::WeightedParticle).
struct ParticleView {
  Position position;  ///< [m]
  Velocity velocity;  ///< [m/s]
  float weight = 0.0f;
};

class DynamicGrid {
 public:
  /// Throws std::invalid_argument when !params.IsValid().
  DynamicGrid(const FilterParams& params, std::uint64_t seed);

  /// One filter cycle. The first call initialises the grid around the ego. `dt` >= 0 [s].
  /// Builds this cycle's measurement grid (as MeasurementGrid::Build on ego.pose.position) and
  /// runs the cycle on it, both in the one parallel region below. The grid's own MeasurementGrid
  /// is allocated at the first call.
  ///
  /// Threads (both Update overloads): one OpenMP parallel region per call, with the team the
  /// calling thread would get (omp_get_max_threads()), barriers between the cycle's stages; no
  /// region at all when a region here would get one thread (dualgrid/core/parallel.hpp,
  /// OneThreadHere: one thread allowed, or the caller is inside a region and no further level may
  /// be active). May be called from inside a parallel region (its region then nests there);
  /// distinct grids may be updated by distinct threads at once. Results are the same bits for any
  /// team size. Threads that wait at a barrier follow OMP_WAIT_POLICY (dualgrid sets PASSIVE).
  void Update(const EgoInput& ego, std::span<const Measurement> measurements,
              std::span<const SensorCoverage> coverage, double dt);
  /// One filter cycle on a measurement grid built for it: `measurement.Build(ego.pose.position,
  /// ...)` with this cycle's detections, after any Reframe. Filters whose params share the
  /// geometry (MeasurementGrid::SharesGeometry) can share one: the co-simulation builds it once per
  /// step for its three modes. Same results, bit for bit, as the Update above with the same
  /// inputs. Only the call's duration reads `measurement`. Throws std::invalid_argument when it
  /// does not share this grid's geometry, was never built, or was built for another position, or
  /// for an ego position beyond FilterParams::kMaxCentre (or not finite).
  /// `noise`, if not null, holds this cycle's prediction normals, drawn once for filters with the
  /// same seed and step (PredictionNoise::Draw(seed, step(), params().num_particles)): read
  /// instead of drawing them, same results bit for bit; std::invalid_argument if it holds others.
  void Update(const EgoInput& ego, const MeasurementGrid& measurement, double dt,
              const PredictionNoise* noise = nullptr);

  /// Turns the caller's frame by `angle` [rad] (counter-clockwise) about its origin, between two
  /// cycles: the caller's next inputs come in the turned frame (the grid that follows the ego's
  /// heading, docs/algorithm.md "Grid frame"). Every particle's position and velocity are mapped
  /// exactly to the new frame (p -> R(-angle) p); the grid is re-centred on `ego` (new frame, as
  /// the next Update's EgoInput will give it) and each new cell takes the free, static and
  /// dynamic masses of the old cell under its centre (nearest cell: no mass is blurred, a cell
  /// moves by at most half a cell diagonal); new cells outside the old grid are unknown. Until the
  /// next Update, weighted_particles() and Cell()'s velocity moments still refer to the old frame.
  /// No-op before the first Update or for angle == 0. O(particles + cells); its scratch layers
  /// are allocated at the first call. Throws std::invalid_argument for a non-finite input or an
  /// ego beyond FilterParams::kMaxCentre.
  void Reframe(double angle, const Position& ego);

  int cells_x() const { return nx_; }
  int cells_y() const { return ny_; }
  double resolution() const { return params_.resolution; }
  /// Number of completed Update calls (the RNG step of the next one).
  std::uint64_t step() const { return step_; }
  bool initialized() const { return initialized_; }

  /// Position of a logical cell's centre in the caller's frame [m].
  Position CellCenter(CellIndex c) const;
  /// Logical cell holding `p`, std::nullopt outside the grid (or before the first Update).
  /// Inline: the scorer calls it for every particle.
  std::optional<CellIndex> CellOf(const Position& p) const;
  /// Throws std::out_of_range for an index outside the grid.
  CellState Cell(CellIndex c) const;
  /// Global index of logical cell (0, 0): its centre is ((gx + 0.5) r, (gy + 0.5) r) [m], the
  /// exact arithmetic of CellCenter, so callers rasterising onto the grid agree with it bit for
  /// bit.
  std::array<std::int64_t, 2> origin_index() const { return {origin_gx_, origin_gy_}; }
  /// Masses [probability] and the observed flag of every cell in logical row-major order (index
  /// y * cells_x() + x), the values Cell() returns, without its velocity moments. Each span must
  /// hold cells_x() * cells_y() entries (std::invalid_argument otherwise). O(cells), no allocation:
  /// the scorer reads this every cycle; figures use Cell() for the velocities only when drawn.
  void ExportMasses(std::span<float> free, std::span<float> static_occ, std::span<float> dynamic,
                    std::span<std::uint8_t> observed) const;
  /// Cell()'s mean_velocity [m/s] of every cell in logical row-major order (as ExportMasses),
  /// cast to float, without the covariance and without locating each cell: the same values as
  /// static_cast<float>(Cell({x, y}).mean_velocity.x()) (and .y()). Each span must hold
  /// cells_x() * cells_y() entries (std::invalid_argument otherwise). O(cells + particles).
  void ExportMeanVelocities(std::span<float> mean_vx, std::span<float> mean_vy) const;

  /// Particles after the last resampling (all `weight`s equal: total dynamic mass / count), in
  /// the caller's frame. The filter keeps them in float grid-local coordinates (docs/algorithm.md,
  /// "Float state"); this copy in double caller coordinates is made at the first call after an
  /// Update or Reframe (O(particles), thread-safe) and kept until the next one.
  const ParticleSet& particles() const;
  /// Persistent particles after the last weight update, before birth and resampling, sorted by
  /// cell: `weight` is the mode's weight normalised so that each cell's weights sum to its
  /// dynamic mass (particles slower than static_speed carry 0). The first
  /// num_weighted_particles() entries are valid. This is the weighted particle set the paper
  /// clusters (Sec. V); after resampling all weights are equal. A copy as particles()' (the frame
  /// of the last Update, also after a Reframe).
  const ParticleSet& weighted_particles() const;
  std::size_t num_weighted_particles() const {
    return cell_start_.empty() ? 0 : static_cast<std::size_t>(cell_start_[num_cells_]);
  }
  /// Entry i < num_weighted_particles() of weighted_particles() without copying the set (the
  /// scorer reads the few particles of dynamic cells every cycle).
  ParticleView WeightedParticle(std::size_t i) const {
    const double r = params_.resolution;
    return {{static_cast<double>(sorted_gx_) * r + sorted_.x[i],
             static_cast<double>(sorted_gy_) * r + sorted_.y[i]},
            {sorted_.vx[i], sorted_.vy[i]},
            sorted_.weight[i]};
  }
  /// Calls f(k, first, last) for every cell holding weighted particles whose value v in `layer`
  /// (logical order, cells_x() * cells_y() entries: e.g. ExportMasses' dynamic layer, or a layer
  /// of eval::CellClass bytes) passes keep(v) (a callable bool(T)), in the order of
  /// weighted_particles(): k = y * cells_x() + x is the logical cell and [first, last) its
  /// particles in weighted_particles(). Every particle of that range has CellOf() == (x, y) (the
  /// sort and CellOf share their arithmetic); particles off the grid are in no range. Scans the
  /// layer and reads a cell's range only where keep(v) holds: cheap when the kept cells are few
  /// and clustered (the scorer's dynamic cells), without locating each particle. With keep a
  /// ByteIs on a byte layer, 8 cells per word (ByteIs). O(cells), no
  /// allocation; nothing before the first Update. Valid between an Update and the next Reframe:
  /// throws std::logic_error after a Reframe (the particles are not sorted into its new cells),
  /// std::invalid_argument for a layer of another size.
  template <typename T, typename Keep, typename F>
  void ForEachWeightedCellWhere(std::span<const T> layer, Keep&& keep, F&& f) const;
  const FilterParams& params() const { return params_; }

  /// The new-born mass of the last Update summed over the cells (step 7's rho_b, the mass its
  /// birth particles are drawn for); 0 before the first Update and after one without detections.
  double NewbornMass() const;

  /// Checks the invariants that hold after every Update (the soak test runs it each cycle):
  /// every cell's masses are finite, in [0, 1] and free + static + dynamic <= 1 (unknown >= 0);
  /// the particle count is num_particles; every particle's position, velocity and weights are
  /// finite, weights >= 0, and the weights sum to no more than the cells' persistent dynamic plus
  /// new-born mass (resampling creates no mass; new-born mass of a cell that got no birth
  /// particle is dropped, so the sum may be lower). Returns a description of the first
  /// violation, std::nullopt if none. O(cells + particles); not called by Update.
  std::optional<std::string> CheckInvariants() const;

 private:
  // Storage index of global cell (gx, gy): circular in both axes so that shifting moves no data.
  std::int64_t Storage(std::int64_t gx, std::int64_t gy) const;
  // Storage column and row of logical cell (0, 0).
  std::array<std::int64_t, 2> StorageOrigin() const;
  // f(i, s, count) for each contiguous storage run of the logical rows (cell_moments.cpp):
  // logical cells [i, i + count) are storage cells [s, s + count), two runs per row.
  template <typename F>
  void ForEachStorageRun(F&& f) const;
  // Initialisation around the ego: the origin (serial), then the particles spread over the grid
  // with zero weight (by the team t).
  void InitializeOrigin(const EgoInput& ego);
  void SpreadParticles(const detail::Team& t);
  void ShiftTo(const Position& ego);
  // Global index of logical cell (0, 0) for a grid centred on `ego`.
  std::array<std::int64_t, 2> OriginFor(const Position& ego) const;
  void ResetColumn(std::int64_t gx);
  void ResetRow(std::int64_t gy);
  // Threads of a cycle (docs/algorithm.md, "One cycle"): Update sizes every scratch buffer
  // (PrepareCycle), then runs Cycle either on the calling thread alone (OneThreadHere: no
  // parallel region at all) or in ONE parallel region, every thread of it calling Cycle with its
  // Team; the stages below are called by every thread of the team in the same order, separated
  // by the team's barriers, and neither allocate nor throw. Each value is computed by one thread
  // from the same inputs, so the results do not depend on the team's size.
  // The checks of Update (throws), then the cycle on `measurement`; with `fill` (the grid's own
  // MeasurementGrid, prepared: MeasurementGrid::Prepare), its tables are filled first, in the
  // same region.
  void Run(const EgoInput& ego, const MeasurementGrid& measurement, double dt,
           const PredictionNoise* noise, MeasurementGrid* fill,
           std::span<const SensorCoverage> coverage);
  void PrepareCycle(std::size_t detections);
  void Cycle(const detail::Team& t, std::span<const Measurement> z, double dt,
             const PredictionNoise* noise, bool first);
  // Prediction (PredictParticles) fused with the counting sort's first pass; `noise` may be null.
  // Also fills this cycle's detection tables (DetectionTables) and view_, beside the sort's scan.
  void PredictAndSort(const detail::Team& t, std::span<const Measurement> z, double dt,
                      const PredictionNoise* noise);
  // This cycle's per-detection tables (det_fv0_, det_fit_k_, the float columns det_f_); serial.
  void DetectionTables(std::span<const Measurement> z);
  // Particle weights (eqs. 7, 8, 14) and occupancy fusion (eqs. 9-12) cell by cell.
  void UpdateCells(const detail::Team& t, std::span<const Measurement> z);
  // The particle kernel's view of the detection tables (pointers into det_f_).
  detail::WeighInputs WeighTables() const;
  // Step 7 in two parts: the birth mass's prefix sums (true when births are to be drawn; false
  // leaves zero-weight births once the team's next barrier is passed), then the births
  // themselves. The sums: block totals `tot` and running sums at each cell chunk's start
  // `chunk_acc`, either the thread's own (few blocks: each thread computes them) or the team's
  // shared born_block_ / born_chunk_acc_.
  struct BirthSums {
    static constexpr int kBlocks = 8, kChunks = 256;  // own arrays: scan blocks, cell chunks
    double own_tot[kBlocks + 1], own_chunk_acc[kChunks];
    const double *tot = nullptr, *chunk_acc = nullptr;
  };
  bool BirthMass(const detail::Team& t, BirthSums& sums);
  void DrawBirths(const detail::Team& t, std::span<const Measurement> z, const BirthSums& sums);
  // The velocity frame of births near detection j, a function of j alone (DrawBirths reuses it
  // across the neighbouring cells that share their nearest detection): the unit line of sight,
  // its tangent, the radial speed and the tangential bound [m/s], the Doppler fit's use. j < 0:
  // no detection.
  struct BirthFrame {
    int j = -1;
    Vector2 los = Vector2::Zero(), tangent = Vector2::Zero();
    double v_radial = 0.0, vt_max = 0.0, fit_t = 0.0, fit_sd = 0.0;
    bool fitted = false;
  };
  BirthFrame FrameOf(std::span<const Measurement> z, int j, double vmax) const;
  // New-born particles [k_lo, k_hi) in storage cell s (each of mass `mass`), their velocities in
  // the frame of the cell's nearest detection.
  void GenerateBirths(std::int64_t s, std::int64_t k_lo, std::int64_t k_hi, double mass,
                      const BirthFrame& f);
  // Step 8: ScanPersistent (serial) may run once the weights are final, beside DrawBirths (it
  // starts the prefix sums over the persistent particles when they fit in one scan block);
  // Resample finishes the sums and copies.
  void ScanPersistent();
  void Resample(const detail::Team& t);

  FilterParams params_;
  // params_ with the per-cycle factors of this cycle's dt (ForCycle): what steps 2-7 read.
  FilterParams cycle_params_;
  std::uint64_t seed_;
  std::uint64_t step_ = 0;
  bool initialized_ = false;
  int nx_, ny_;
  std::int64_t num_cells_;
  std::int64_t origin_gx_ = 0, origin_gy_ = 0;  // global index of logical cell (0, 0)
  bool sorted_current_ = false;  // sorted_ is binned on the current cells (no Reframe since)

  // Cell layers (storage order).
  std::vector<double> free_, static_, dynamic_, born_;
  std::vector<std::uint8_t> view_;  // the last cycle's MeasurementGrid bits (Cell, ExportMasses)

  // Particles (float, grid-local metres): persistent set, sorted working copy, new-born.
  detail::LocalParticles particles_, sorted_, births_;
  // Whole cells the grid moved in this cycle's ShiftTo, subtracted in the prediction's pass.
  std::int64_t shift_gx_ = 0, shift_gy_ = 0;
  // Origin of the cells sorted_ is sorted on (weighted_particles(): the frame of the last Update).
  std::int64_t sorted_gx_ = 0, sorted_gy_ = 0;
  // particles() / weighted_particles() in the caller's frame, made on demand under the lock.
  struct Exported {
    ParticleSet set;
    bool valid = false;
  };
  struct ExportLock {  // copies and moves make a new mutex
    std::mutex m;
    ExportLock() = default;
    ExportLock(const ExportLock&) {}
    ExportLock& operator=(const ExportLock&) { return *this; }
  };
  mutable Exported exported_, exported_weighted_;
  mutable ExportLock export_lock_;
  void InvalidateExports() { exported_.valid = exported_weighted_.valid = false; }
  // `out`, made from `in` (grid-local, origin (gx, gy)) unless still valid.
  const ParticleSet& ExportOnce(Exported& out, const detail::LocalParticles& in, std::int64_t gx,
                                std::int64_t gy) const;
  detail::AlignedVector<std::int32_t> cell_of_;  // storage cell per particle, num_cells_ if outside
  std::vector<std::int64_t> cell_start_;         // num_cells_ + 2: particle ranges of sorted_
  std::vector<std::int32_t> hist_;               // per-chunk histograms of the counting sort
  std::vector<std::int64_t> hist_total_;
  std::vector<double> scan_out_;               // resampling prefix sums of the source weights
  std::vector<double> scan_base_;              // their block totals
  std::vector<std::uint32_t> resample_owner_;  // Resample's scratch: each output slot's source
  double scan_persistent_ = 0.0;               // ScanPersistent's running sum
  std::vector<double> born_block_;             // block totals of the birth-mass prefix sums
  // Cells with non-zero birth mass, per UpdateCells chunk (slots [chunk * size, + count)).
  std::vector<std::int64_t> born_cells_;
  std::vector<std::int32_t> born_count_;
  std::vector<double> det_fv0_;         // per detection: f_v of a particle at v = 0
  std::vector<double> born_chunk_acc_;  // birth-mass running sum at each chunk start
  // The births' draws of this cycle, made for all num_birth at once (DrawBirths): slot
  // c * num_birth + k holds birth k's uniform c (c 0, 1, 4, 5) or normal c (c 2, 3).
  std::vector<float> birth_draw_;
  // The measurement grid of the running Update (the caller's or own_measurement_); null between
  // cycles.
  const MeasurementGrid* mg_ = nullptr;
  std::optional<MeasurementGrid> own_measurement_;  // the first standalone Update makes it
  std::vector<double> reframe_layers_;  // Reframe: the old free, static and dynamic layers
  std::vector<double> det_fit_k_;       // radial_fit: 1 / (2 (sigma_v^2 + s_t^2)) per detection
  detail::AlignedVector<float> det_f_;  // WeighTables' columns
  detail::CandidateIndex candidates_;   // the particle weights' candidates (DetectionTables)
};

inline std::optional<CellIndex> DynamicGrid::CellOf(const Position& p) const {
  if (!initialized_ || !p.allFinite()) return std::nullopt;
  // The particles' grid-local float metres and the sort's arithmetic (PredictAndSort): a
  // position of weighted_particles() gives back the particle's own float, so its cell is the one
  // it was weighed in, whatever the resolution.
  const double r = params_.resolution;
  const float inv_r = static_cast<float>(1.0 / r);
  const float fx =
      std::floor(static_cast<float>(p.x() - static_cast<double>(origin_gx_) * r) * inv_r);
  const float fy =
      std::floor(static_cast<float>(p.y() - static_cast<double>(origin_gy_) * r) * inv_r);
  if (!(fx >= 0.0f && fy >= 0.0f && fx < static_cast<float>(nx_) && fy < static_cast<float>(ny_)))
    return std::nullopt;
  return CellIndex{static_cast<int>(fx), static_cast<int>(fy)};
}

template <typename T, typename Keep, typename F>
void DynamicGrid::ForEachWeightedCellWhere(std::span<const T> layer, Keep&& keep, F&& f) const {
  if (!initialized_ || cell_start_.empty()) return;  // no particles before the first Update
  if (!sorted_current_)
    throw std::logic_error(
        "DynamicGrid::ForEachWeightedCellWhere: called after Reframe, before Update");
  if (layer.size() != static_cast<std::size_t>(num_cells_))
    throw std::invalid_argument("DynamicGrid::ForEachWeightedCellWhere: layer of " +
                                std::to_string(layer.size()) + " cells for " +
                                std::to_string(num_cells_));
  // ByteIs on bytes (little-endian): 8 cells per 64-bit word.
  constexpr bool kWords = std::is_same_v<T, std::uint8_t> &&
                          std::is_same_v<std::remove_cvref_t<Keep>, ByteIs> &&
                          std::endian::native == std::endian::little;
  const auto [sx0, sy0] = StorageOrigin();
  for (std::int64_t sy = 0; sy < ny_; ++sy) {
    const std::int64_t y = sy >= sy0 ? sy - sy0 : sy - sy0 + ny_;
    const T* const row = layer.data() + y * nx_;
    const std::int64_t* const start = cell_start_.data() + sy * nx_;
    // Storage columns [0, sx0) hold logical x = sx + nx - sx0, columns [sx0, nx) x = sx - sx0:
    // two contiguous runs of the logical row, visited in storage (= particle) order.
    const auto visit = [&](std::int64_t sx, std::int64_t x_off) {
      if (start[sx] != start[sx + 1])
        f(static_cast<std::size_t>(y * nx_ + sx + x_off), start[sx], start[sx + 1]);
    };
    const auto run = [&](std::int64_t sx_lo, std::int64_t sx_hi, std::int64_t x_off) {
      std::int64_t sx = sx_lo;
      if constexpr (kWords) {
        constexpr std::uint64_t kLow7 = 0x7f7f7f7f7f7f7f7fULL;
        const std::uint64_t ones_value = 0x0101010101010101ULL * keep.value;
        for (; sx + 8 <= sx_hi; sx += 8) {
          std::uint64_t w;
          std::memcpy(&w, row + sx + x_off, sizeof w);
          w ^= ones_value;  // kept bytes are 0; m: bit 7 of exactly those (no carry across bytes)
          std::uint64_t m = ~(((w & kLow7) + kLow7) | w | kLow7);
          for (; m != 0; m &= m - 1)
            visit(sx + std::countr_zero(m) / 8, x_off);  // low address first
        }
      }
      for (; sx < sx_hi; ++sx)
        if (keep(row[sx + x_off])) visit(sx, x_off);
    };
    run(0, sx0, nx_ - sx0);
    run(sx0, nx_, -sx0);
  }
}

}  // namespace dualgrid::filter
