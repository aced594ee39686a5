// The floor of issue 37's new design (docs/performance.md, "Issue 37, second part"): a kernel
// doing a dual-weight filter cycle's least work in float on SIMD lanes (Highway, the filter's
// pinned SSE4 target), in ONE OpenMP parallel region per cycle. Not a filter: it does the work
// of every stage of DynamicGrid::Update with DynamicGrid's data sizes and access patterns, but
// not every branch of its equations (one weight mode, one likelihood, no switches). Benchmark
// only (bench_filter --benchmark_filter=FloorCycle).
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "dualgrid/core/types.hpp"
#include "dualgrid/filter/measurement_grid.hpp"

namespace dualgrid::bench {

/// Float SoA particles in grid-local metres.
struct FloorParticles {
  std::vector<float> x, y, vx, vy, weight, w_position, w_velocity;
  void resize(std::size_t n);
};

/// One cycle's work at a grid of nx x ny cells of `resolution` [m] with `particles` persistent
/// and `births` new-born particles. Run() is one cycle: the measurement grid (nearest detection
/// per cell, detection buckets, bearing bins, the field of view's bits per cell), the prediction
/// fused with the Philox normals (simd_normals.hpp), the cell index and the counting sort's
/// histogram, the sort's scatter, the fused weight / per-cell sum / occupancy pass on float
/// layers, births by systematic allocation, systematic resampling.
class FloorCycle {
 public:
  FloorCycle(int particles, int births, int nx, int ny, double resolution, std::uint64_t seed);

  /// One cycle at ego position `centre` [m] (the grid is centred there, whole cells), dt [s].
  /// Uses the caller's OpenMP thread count; results do not depend on it.
  void Run(const Position& centre, std::span<const filter::Measurement> z,
           std::span<const filter::SensorCoverage> coverage, double dt);

  /// Sum of the cells' dynamic mass (a check that the work happened).
  double DynamicMass() const;
  /// Cells holding particles and cells with a detection within the cutoff (the cell pass's
  /// per-cell work), after the last Run.
  std::int64_t CellsWithParticles() const;
  std::int64_t CellsWithDetection() const;
  /// Thread 0's CPU time [s] per phase summed over all runs (0 measurement grid, 1 prediction,
  /// 2 sort, 3 cell pass, 4 births, 5 resampling; with the waits at the phase's barriers).
  const std::array<double, 6>& PhaseCpu() const { return phase_cpu_; }

 private:
  struct Det {   // a detection, grid-local, in bucket order
    float x, y;  // [m]
    int item;    // index in the cycle's z
  };
  struct Sensor {
    float ox, oy, cb, sb, tan_hf, half_fov, min2, max2;  // [m], [rad], [m^2]
    int bin0, bins;
  };
  void Inputs(const Position& centre, std::span<const filter::Measurement> z,
              std::span<const filter::SensorCoverage> coverage);
  void MeasurementRows(int y_lo, int y_hi);
  void ViewRows(int y_lo, int y_hi);
  void Sort(int t, int nt);
  void Predict(int t, int threads, float dt);
  struct CellSums {  // a cell's particle sums (WeighCell)
    double slow, fast, pos, vel, dyn;
  };
  void CellChunk(std::int64_t ch);
  void QuietCells(std::int64_t c_lo, std::int64_t c_hi);
  double UpdateCell(std::int64_t c);
  CellSums WeighCell(std::int32_t lo, std::int32_t hi, float cap, bool observed);
  void NormaliseCell(std::int32_t lo, std::int32_t hi, double rho_p, double sum_pos,
                     double sum_vel);
  void BirthChunk(std::int64_t ch, double total, float u0);
  void ResampleBlock(std::int64_t b, double total, double u0);
  void Mark(int thread, int phase);

  int n_, nb_, nx_, ny_;
  std::int64_t cells_;
  float r_;
  std::uint64_t seed_, step_ = 0;
  std::int64_t gx_ = 0, gy_ = 0;  // grid origin [cells]
  bool started_ = false;
  int shift_x_ = 0, shift_y_ = 0;  // whole cells moved this cycle
  FloorParticles p_, s_;           // state; sorted (with the births after the persistent ones)
  std::vector<std::int32_t> cell_of_, hist_, start_, block_total_;
  std::vector<float> free_, static_, dynamic_, born_;
  std::vector<std::uint8_t> view_;
  std::vector<std::int32_t> near_, born_list_, born_n_;
  std::vector<float> near_d2_;
  std::vector<double> chunk_born_, block_w_;
  // Detections: buckets (bucket_cells_ cells wide), bucket order, per item tables.
  int bucket_cells_, nbx_, nby_;
  std::vector<std::int32_t> bucket_start_, bucket_of_;
  std::vector<Det> det_;
  std::vector<float> u0_, u1_, u2_, bin_range_;
  std::vector<Sensor> sensors_;
  int hist_threads_ = 0;
  double mark_ = 0.0;
  std::array<double, 6> phase_cpu_{};
};

}  // namespace dualgrid::bench
