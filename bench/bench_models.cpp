// Speed of the radar model's Scan and of eval's ParticleClusterer (docs/performance.md).
//   bench_models --benchmark_filter=RadarScan   (highway: 40 vehicles, 2 guard rails, DefaultRig;
//                                                RadarScanLongRails: each rail one straight
//                                                segment)
//   bench_models --benchmark_filter=Multipath   (the same scan, multipath off and on side by side)
//   bench_models --benchmark_filter=Clusterer   (10,000 particles on 8 vehicles)
// Argument: OpenMP threads.
#include <benchmark/benchmark.h>

#include <chrono>
#include <cmath>
#include <vector>

#include <omp.h>

#include "dualgrid/core/random.hpp"
#include "dualgrid/core/types.hpp"
#include "dualgrid/eval/clustering.hpp"
#include "dualgrid/radar_model/radar_model.hpp"

using namespace dualgrid;

namespace {

// Four-lane highway (3.5 m lanes, y in [-7, 7]) with a guard rail on each side (y = +-8.5 m, 600 m
// long) and 40 vehicles within 150 m of the ego (centre of lane 2, 30 m/s). The rails are
// polylines of 10 m segments, or with `long_rails` one segment each (as the scenarios' rails).
radar::Scene HighwayScene(bool long_rails = false) {
  radar::Scene scene;
  for (int i = 0; i < 40; ++i) {
    CounterRng rng(7, RngPurpose::kTest, 0, static_cast<std::uint32_t>(i));
    const int lane = i % 4;
    const bool truck = rng.Uniform() < 0.15;
    radar::Target t;
    t.id = i;
    t.box.center = {-150.0 + 300.0 * (i + rng.Uniform(0.1, 0.9)) / 40.0, -5.25 + 3.5 * lane};
    t.box.yaw = rng.Uniform(-0.02, 0.02);
    t.box.length = truck ? 12.0 : 4.5;
    t.box.width = truck ? 2.5 : 1.8;
    t.velocity = Velocity(rng.Uniform(22.0, 38.0), 0.0);
    t.rcs_dbsm = truck ? 20.0 : 10.0;
    scene.targets.push_back(t);
  }
  for (const double y : {-8.5, 8.5}) {
    radar::Polyline rail;
    rail.id = 1000 + static_cast<int>(y > 0);
    for (double x = -300.0; x <= 300.0; x += long_rails ? 600.0 : 10.0)
      rail.points.push_back({x, y});
    scene.polylines.push_back(rail);
  }
  return scene;
}

// One Scan of all sensors due at time 0 (every sensor fires): detections of the whole rig.
void RadarScan(benchmark::State& state, bool long_rails) {
  omp_set_num_threads(static_cast<int>(state.range(0)));
  const radar::RadarModel model(radar::DefaultRig(4.5, 1.8), radar::ModelOptions{}, 1);
  const radar::Scene scene = HighwayScene(long_rails);
  radar::EgoMotion ego;
  ego.pose = Pose2{Position(0.0, -1.75), 0.0};
  ego.velocity = Velocity(30.0, 0.0);
  std::uint64_t step = 0;
  std::size_t detections = 0;
  for (auto _ : state) {
    const std::vector<radar::Detection> z = model.Scan(ego, scene, step++, 0.0, 0.05);
    detections = z.size();
    benchmark::DoNotOptimize(z.data());
  }
  state.SetItemsProcessed(state.iterations());  // items/s = scans per second
  state.counters["sensors"] = static_cast<double>(model.sensors().size());
  state.counters["targets"] = static_cast<double>(scene.targets.size());
  state.counters["detections"] = static_cast<double>(detections);
}
void BM_RadarScan(benchmark::State& state) { RadarScan(state, false); }
void BM_RadarScanLongRails(benchmark::State& state) { RadarScan(state, true); }
BENCHMARK(BM_RadarScan)->Arg(1)->Arg(2)->Unit(benchmark::kMicrosecond)->UseRealTime();
BENCHMARK(BM_RadarScanLongRails)->Arg(1)->Arg(2)->Unit(benchmark::kMicrosecond)->UseRealTime();

// The cost of multipath (issue 27: at most +20 % on a sim step): every iteration scans the same
// scene with multipath off and then on, each timed, so that both see the same machine load; the
// counters give the mean time of each and their ratio. Arguments: OpenMP threads; the ego's lane
// (1: as BM_RadarScan, 5.25 m from the right rail; 3: the left lane, 3.25 m from the left rail).
void BM_MultipathCost(benchmark::State& state) {
  omp_set_num_threads(static_cast<int>(state.range(0)));
  radar::ModelOptions on_options;
  on_options.multipath.enabled = true;
  const radar::RadarModel off(radar::DefaultRig(4.5, 1.8), radar::ModelOptions{}, 1);
  const radar::RadarModel on(radar::DefaultRig(4.5, 1.8), on_options, 1);
  const radar::Scene scene = HighwayScene();
  radar::EgoMotion ego;
  ego.pose = Pose2{Position(0.0, -5.25 + 3.5 * static_cast<double>(state.range(1))), 0.0};
  ego.velocity = Velocity(30.0, 0.0);
  ego.length = 4.5;
  ego.width = 1.8;
  using Clock = std::chrono::steady_clock;
  std::uint64_t step = 0;
  double off_s = 0.0, on_s = 0.0;
  std::size_t off_n = 0, on_n = 0, ghosts = 0;
  for (auto _ : state) {
    const auto t0 = Clock::now();
    const std::vector<radar::Detection> a = off.Scan(ego, scene, step, 0.0, 0.05);
    const auto t1 = Clock::now();
    const std::vector<radar::Detection> b = on.Scan(ego, scene, step, 0.0, 0.05);
    const auto t2 = Clock::now();
    ++step;
    off_s += std::chrono::duration<double>(t1 - t0).count();
    on_s += std::chrono::duration<double>(t2 - t1).count();
    off_n = a.size();
    on_n = b.size();
    ghosts = 0;
    for (const radar::Detection& d : b) ghosts += d.path != radar::Path::kDirect;
    benchmark::DoNotOptimize(a.data());
    benchmark::DoNotOptimize(b.data());
  }
  const double n = static_cast<double>(state.iterations());
  state.counters["off_us"] = 1e6 * off_s / n;
  state.counters["on_us"] = 1e6 * on_s / n;
  state.counters["ratio"] = on_s / off_s;
  state.counters["detections_off"] = static_cast<double>(off_n);
  state.counters["detections_on"] = static_cast<double>(on_n);
  state.counters["ghosts"] = static_cast<double>(ghosts);
}
BENCHMARK(BM_MultipathCost)
    ->Args({1, 1})
    ->Args({2, 1})
    ->Args({1, 3})
    ->Unit(benchmark::kMicrosecond)
    ->UseRealTime();

// 10,000 weighted particles on 8 vehicles (uniform in each 4.5 m x 1.8 m box, 1,250 each) plus
// 500 spread uniformly over the road (mostly DBSCAN noise), as the filter hands over its dynamic
// cells.
void BM_Clusterer(benchmark::State& state) {
  omp_set_num_threads(static_cast<int>(state.range(0)));
  std::vector<eval::WeightedParticle> particles;
  constexpr int kVehicles = 8, kPerVehicle = 1250;
  for (int v = 0; v < kVehicles; ++v) {
    const Position c(-80.0 + 20.0 * v, -5.25 + 3.5 * (v % 4));
    const Velocity vel(25.0 + v, 0.0);
    for (int k = 0; k < kPerVehicle; ++k) {
      CounterRng rng(3, RngPurpose::kTest, static_cast<std::uint64_t>(v),
                     static_cast<std::uint32_t>(k));
      eval::WeightedParticle p;
      p.position = c + Vector2(rng.Uniform(-2.25, 2.25), rng.Uniform(-0.9, 0.9));
      p.velocity = vel + Vector2(rng.Normal(0.0, 1.5), rng.Normal(0.0, 0.5));
      p.weight = rng.Uniform(0.5, 1.5) * 1e-4;
      particles.push_back(p);
    }
  }
  for (int k = 0; k < 500; ++k) {
    CounterRng rng(3, RngPurpose::kTest, 99, static_cast<std::uint32_t>(k));
    eval::WeightedParticle p;
    p.position = {rng.Uniform(-100.0, 100.0), rng.Uniform(-7.0, 7.0)};
    p.velocity = {rng.Uniform(0.0, 40.0), 0.0};
    p.weight = 1e-4;
    particles.push_back(p);
  }
  eval::ParticleClusterer clusterer;
  std::size_t clusters = 0;
  for (auto _ : state) {
    const std::vector<eval::Cluster> out = clusterer.Run(particles);
    clusters = out.size();
    benchmark::DoNotOptimize(out.data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(particles.size()));
  state.counters["particles"] = static_cast<double>(particles.size());
  state.counters["clusters"] = static_cast<double>(clusters);
}
BENCHMARK(BM_Clusterer)->Arg(1)->Arg(2)->Unit(benchmark::kMicrosecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
