// Cycle time of DynamicGrid::Update at the paper's configuration and at scale.
//   bench_filter --benchmark_filter=Paper    (10k particles, 200 m x 25 m at 0.5 m)
//   bench_filter --benchmark_filter=Scale    (1e5 .. 2e6 particles, 10 % births, 1.4e6 cells)
//   bench_filter --benchmark_filter=Floor    (floors: the noise, one pass, a whole float cycle)
//   bench_filter --benchmark_filter=Barrier  (what a barrier's wake-up costs on this machine)
// Arguments: particles, threads (OpenMP). Results: docs/performance.md.
#include <benchmark/benchmark.h>

#include <cmath>
#include <vector>

#include <omp.h>

#include "dualgrid/core/random.hpp"
#include "dualgrid/core/types.hpp"
#include "dualgrid/filter/dynamic_grid.hpp"
#include "dualgrid/filter/particles.hpp"
#include "dualgrid/filter/prediction_noise.hpp"
#include "floor_cycle.hpp"

using namespace dualgrid;
using namespace dualgrid::filter;

namespace {

struct Target {
  Position p;
  Velocity v;
};

// A synthetic traffic scene around an ego driving along x at 25 m/s: `targets` vehicles at
// 20-36 m/s (some static) spread over the grid, `per_target` exact detections each from the
// nearest of the given sensors (long-range front radar + four corner radars).
class Scene {
 public:
  // `rail_points` > 0 adds two guard rails (static, 1 m inside the grid's long sides) returning
  // that many detections each per cycle: the bulk of the highway's ~700 detections per step.
  Scene(double length, double width, int targets, int per_target, double sensor_range,
        int rail_points = 0)
      : length_(length),
        width_(width),
        per_target_(per_target),
        range_(sensor_range),
        rail_points_(rail_points) {
    for (int i = 0; i < targets; ++i) {
      CounterRng rng(42, RngPurpose::kTest, 0, static_cast<std::uint32_t>(i));
      const bool parked = rng.Uniform() < 0.2;
      targets_.push_back({{rng.Uniform(-0.45, 0.45) * length, rng.Uniform(-0.45, 0.45) * width},
                          parked ? Velocity(0, 0) : Velocity(rng.Uniform(20.0, 36.0), 0.0)});
    }
  }

  void Step(double dt, std::uint64_t step) {
    ego_.position.x() += 25.0 * dt;
    for (Target& t : targets_) {
      t.p += t.v * dt;
      // Keep targets inside the window around the ego (wrap along x).
      const double rel = t.p.x() - ego_.position.x();
      if (rel > 0.45 * length_) t.p.x() -= 0.9 * length_;
      if (rel < -0.45 * length_) t.p.x() += 0.9 * length_;
    }
    coverage_.clear();
    const double hl = 2.3, hw = 0.9;
    coverage_.push_back({ego_.ToParent({hl, 0}), 0.0, DegToRad(10), 0.5, range_});
    for (const auto& [x, y, b] : {std::tuple{hl, hw, 0.8}, std::tuple{hl, -hw, -0.8},
                                  std::tuple{-hl, hw, 2.4}, std::tuple{-hl, -hw, -2.4}}) {
      coverage_.push_back({ego_.ToParent({x, y}), b, DegToRad(75), 0.3, 0.5 * range_});
    }
    z_.clear();
    for (std::size_t i = 0; i < targets_.size(); ++i) {
      const Target& t = targets_[i];
      CounterRng rng(42, RngPurpose::kTest, step, static_cast<std::uint32_t>(i));
      const SensorCoverage& s = t.p.x() >= ego_.position.x() ? coverage_[0] : coverage_[3];
      for (int k = 0; k < per_target_; ++k) {
        const Position p = t.p + Vector2(rng.Uniform(-2.2, 2.2), rng.Uniform(-0.9, 0.9));
        const Vector2 los = (p - s.origin).normalized();
        z_.push_back({p, t.v.dot(los) * los, s.origin});
      }
    }
    for (int side = 0; side < 2 && rail_points_ > 0; ++side) {
      CounterRng rng(43, RngPurpose::kTest, step, static_cast<std::uint32_t>(side));
      const double y = (side == 0 ? 1.0 : -1.0) * (0.5 * width_ - 1.0);
      for (int k = 0; k < rail_points_; ++k) {
        const Position p(ego_.position.x() + rng.Uniform(-0.45, 0.45) * length_,
                         ego_.position.y() + y);
        const SensorCoverage& s = p.x() >= ego_.position.x() ? coverage_[side == 0 ? 1 : 2]
                                                             : coverage_[side == 0 ? 3 : 4];
        z_.push_back({p, Vector2::Zero(), s.origin});
      }
    }
  }

  EgoInput ego() const { return {ego_, {25.0, 0.0}}; }
  const std::vector<Measurement>& z() const { return z_; }
  const std::vector<SensorCoverage>& coverage() const { return coverage_; }

 private:
  double length_, width_;
  int per_target_;
  double range_;
  int rail_points_;
  Pose2 ego_;
  std::vector<Target> targets_;
  std::vector<Measurement> z_;
  std::vector<SensorCoverage> coverage_;
};

void RunCycles(benchmark::State& state, const FilterParams& fp, Scene& scene) {
  omp_set_num_threads(static_cast<int>(state.range(1)));
  DynamicGrid grid(fp, 1);
  std::uint64_t step = 0;
  for (int k = 0; k < 20; ++k) {  // warm-up: steady particle distribution
    scene.Step(0.05, step++);
    grid.Update(scene.ego(), scene.z(), scene.coverage(), 0.05);
  }
  for (auto _ : state) {
    state.PauseTiming();
    scene.Step(0.05, step++);
    state.ResumeTiming();
    grid.Update(scene.ego(), scene.z(), scene.coverage(), 0.05);
  }
  state.SetItemsProcessed(state.iterations());  // items/s = cycles per second
  state.counters["particles"] = static_cast<double>(fp.num_particles);
  state.counters["births"] = static_cast<double>(fp.num_birth);
  state.counters["cells"] = static_cast<double>(grid.cells_x()) * grid.cells_y();
  state.counters["detections"] = static_cast<double>(scene.z().size());
}

// Paper configuration: 200 m x 25 m at 0.5 m (20,000 cells), 10,000 particles, 1,000 births,
// 10 vehicles with 5 detections each.
void BM_PaperConfig(benchmark::State& state) {
  FilterParams fp;
  fp.num_particles = static_cast<int>(state.range(0));
  fp.num_birth = fp.num_particles / 10;
  Scene scene(fp.length_x, fp.width_y, 10, 5, 200.0);
  RunCycles(state, fp, scene);
}
BENCHMARK(BM_PaperConfig)
    ->Args({10000, 1})
    ->Args({10000, 2})
    ->Unit(benchmark::kMicrosecond)
    ->UseRealTime();

// Paper size with a highway-like load: 20 vehicles x 10 detections plus two guard rails with 250
// static returns each (700 detections per cycle, the highway scenario's average).
void BM_PaperHighway(benchmark::State& state) {
  FilterParams fp;
  fp.num_particles = static_cast<int>(state.range(0));
  fp.num_birth = fp.num_particles / 10;
  Scene scene(fp.length_x, fp.width_y, 20, 10, 200.0, 250);
  RunCycles(state, fp, scene);
}
BENCHMARK(BM_PaperHighway)
    ->Args({10000, 1})
    ->Args({10000, 2})
    ->Unit(benchmark::kMicrosecond)
    ->UseRealTime();

// At scale: 1000 m x 350 m at 0.5 m (1.4e6 cells), 10 % births, 400 vehicles x 5 detections.
void BM_Scale(benchmark::State& state) {
  FilterParams fp;
  fp.length_x = 1000.0;
  fp.width_y = 350.0;
  fp.num_particles = static_cast<int>(state.range(0));
  fp.num_birth = fp.num_particles / 10;
  Scene scene(fp.length_x, fp.width_y, 400, 5, 500.0);
  RunCycles(state, fp, scene);
}
BENCHMARK(BM_Scale)
    ->Args({100000, 2})
    ->Args({1000000, 1})
    ->Args({1000000, 2})
    ->Args({2000000, 1})
    ->Args({2000000, 2})
    ->Unit(benchmark::kMillisecond)
    ->MinTime(2.0)
    ->UseRealTime();

// The floor of issue 25's paper-size rows (docs/performance.md, round 6): work that no
// arrangement of the cycle avoids under the rules, at the paper's size (10,000 particles,
// 1,000 births, 20,000 cells) and at Nuss scale (2e6 particles, 2e5 births, 1.44e6 cells).
// Arguments: particles, threads[, cells].
//   bench_filter --benchmark_filter=Floor
// 1. The prediction's process noise: four standard normals per particle from Philox keyed by
//    seed, step and particle index (the determinism rule), drawn as the filter draws them.
void BM_FloorNoise(benchmark::State& state) {
  omp_set_num_threads(static_cast<int>(state.range(1)));
  PredictionNoise noise;
  std::uint64_t step = 0;
  for (auto _ : state) {
    noise.Draw(1, step++, state.range(0));
    benchmark::DoNotOptimize(noise.channel(0));
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_FloorNoise)
    ->Args({10000, 1})
    ->Args({10000, 2})
    ->Args({2000000, 2})
    ->Unit(benchmark::kMicrosecond)
    ->UseRealTime();

// 2. One pass that reads and writes every particle (the ParticleSet's 36 bytes, 11,000 with the
//    births) and every cell (four double mass layers), with the least arithmetic a pass has:
//    a constant-velocity step and a decay. The cycle needs at least four such passes over the
//    particles (prediction, sort, weights, resampling) and two over the cells (update, export).
void BM_FloorPass(benchmark::State& state) {
  omp_set_num_threads(static_cast<int>(state.range(1)));
  const std::int64_t n = state.range(0) + state.range(0) / 10, cells = state.range(2);
  ParticleSet q;
  q.resize(static_cast<std::size_t>(n));
  for (std::int64_t i = 0; i < n; ++i) {
    q.x[i] = 0.01 * i;
    q.y[i] = 0.02 * i;
    q.vx[i] = q.vy[i] = 1.0f;
    q.w_position[i] = q.w_velocity[i] = q.weight[i] = 1e-4f;
  }
  std::vector<double> f(cells, 0.1), s(cells, 0.1), d(cells, 0.1), b(cells, 0.0);
  for (auto _ : state) {
#pragma omp parallel
    {
#pragma omp for schedule(static) nowait
      for (std::int64_t i = 0; i < n; ++i) {
        q.x[i] += 0.05 * q.vx[i];
        q.y[i] += 0.05 * q.vy[i];
        // Affine updates with fixed points: no value decays into the subnormals (slow).
        q.vx[i] = 0.999f * q.vx[i] + 0.001f;
        q.vy[i] = 0.999f * q.vy[i] + 0.001f;
        q.w_position[i] = 0.99f * q.w_position[i] + 1e-6f;
        q.w_velocity[i] = 0.99f * q.w_velocity[i] + 1e-6f;
        q.weight[i] = 0.99f * q.weight[i] + 1e-6f;
      }
#pragma omp for schedule(static)
      for (std::int64_t c = 0; c < cells; ++c) {
        f[c] = 0.9 * f[c] + 0.01;
        s[c] = 0.98 * s[c] + 0.002;
        d[c] = 1.0 - f[c] - s[c];
        b[c] = 0.5 * d[c];
      }
    }
    benchmark::DoNotOptimize(q.x.data());
    benchmark::DoNotOptimize(b.data());
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_FloorPass)
    ->Args({10000, 1, 20000})
    ->Args({10000, 2, 20000})
    ->Args({2000000, 2, 1440000})
    ->Unit(benchmark::kMicrosecond)
    ->UseRealTime();

// 3. The floor of issue 37's new design: FloorCycle (floor_cycle.hpp), a whole cycle's least work
//    in float on SSE4 lanes in one parallel region, on the scenes of BM_PaperConfig (kind 0: 50
//    detections), BM_PaperHighway (1: 700 detections) and BM_Scale at Nuss scale (2: 2e6 + 2e5
//    particles, 1.4e6 cells, 2,000 detections). Arguments: kind, threads.
void BM_FloorCycle(benchmark::State& state) {
  omp_set_num_threads(static_cast<int>(state.range(1)));
  const int kind = static_cast<int>(state.range(0));
  FilterParams fp;
  if (kind == 2) {
    fp.length_x = 1000.0;
    fp.width_y = 350.0;
    fp.num_particles = 2000000;
  }
  fp.num_birth = fp.num_particles / 10;
  Scene scene = kind == 0   ? Scene(fp.length_x, fp.width_y, 10, 5, 200.0)
                : kind == 1 ? Scene(fp.length_x, fp.width_y, 20, 10, 200.0, 250)
                            : Scene(fp.length_x, fp.width_y, 400, 5, 500.0);
  bench::FloorCycle floor(fp.num_particles, fp.num_birth, fp.CellsX(), fp.CellsY(), fp.resolution,
                          1);
  std::uint64_t step = 0;
  for (int k = 0; k < 20; ++k) {  // warm-up, as RunCycles
    scene.Step(0.05, step++);
    floor.Run(scene.ego().pose.position, scene.z(), scene.coverage(), 0.05);
  }
  const std::array<double, 6> warm = floor.PhaseCpu();
  for (auto _ : state) {
    state.PauseTiming();
    scene.Step(0.05, step++);
    state.ResumeTiming();
    floor.Run(scene.ego().pose.position, scene.z(), scene.coverage(), 0.05);
  }
  const char* names[6] = {"us_mgrid", "us_predict", "us_sort",
                          "us_cells", "us_birth",   "us_resample"};
  for (int k = 0; k < 6; ++k) {
    state.counters[names[k]] =
        1e6 * (floor.PhaseCpu()[k] - warm[k]) / static_cast<double>(state.iterations());
  }
  state.SetItemsProcessed(state.iterations());
  state.counters["detections"] = static_cast<double>(scene.z().size());
  state.counters["dynamic_mass"] = floor.DynamicMass();
  state.counters["cells_particles"] = static_cast<double>(floor.CellsWithParticles());
  state.counters["cells_detection"] = static_cast<double>(floor.CellsWithDetection());
}
BENCHMARK(BM_FloorCycle)
    ->Args({0, 1})
    ->Args({0, 2})
    ->Args({1, 1})
    ->Args({1, 2})
    ->Args({2, 1})
    ->Args({2, 2})
    ->Unit(benchmark::kMicrosecond)
    ->UseRealTime();

// 4. What one barrier of the cycle's region costs on this machine (docs/performance.md, issue
//    37, third part): two threads cross 200 barriers; before each, thread 0 works `late` us
//    (argument) while thread 1 waits, so with OMP_WAIT_POLICY=PASSIVE it sleeps and must be
//    woken. Counter us_per_barrier: wall time per barrier beyond the work.
double BusyFor(double us) {
  const double t0 = omp_get_wtime();
  double x = 0.0;
  while ((omp_get_wtime() - t0) * 1e6 < us) x += 1.0;
  return x;
}

void BM_BarrierWake(benchmark::State& state) {
  const double late = static_cast<double>(state.range(0));
  constexpr int kBarriers = 200;
  double sink = 0.0, spent = 0.0;
  for (auto _ : state) {
    const double t0 = omp_get_wtime();
#pragma omp parallel num_threads(2) reduction(+ : sink)
    for (int k = 0; k < kBarriers; ++k) {
      if (omp_get_thread_num() == 0) sink += BusyFor(late);
#pragma omp barrier
    }
    spent += omp_get_wtime() - t0;
  }
  benchmark::DoNotOptimize(sink);
  state.counters["us_per_barrier"] =
      1e6 * spent / (static_cast<double>(state.iterations()) * kBarriers) - late;
}
BENCHMARK(BM_BarrierWake)->Arg(1)->Arg(20)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
