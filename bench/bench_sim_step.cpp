// The cost of multipath on a `dualgrid sim` step (issue 27: at most +20 %), side by side: every
// iteration runs the highway scenario's first `steps` steps through the co-simulation without
// filters (SUMO, the radar and the filters' inputs: what `dualgrid sim` computes per step) with
// sensors.multipath off and on, alternating which goes first, and times the steps only (SUMO's
// start is not a step). Counters: mean time per step of each, their ratio, ghosts per step.
//   bench_sim_step --benchmark_filter=SimStep     (argument: OpenMP threads)
// The radar scan alone: bench_models --benchmark_filter=Multipath.
#include <benchmark/benchmark.h>

#include <chrono>
#include <filesystem>
#include <string>

#include <omp.h>

#include "dualgrid/cosim/cosimulation.hpp"
#include "dualgrid/scenario/loader.hpp"
#include "dualgrid/sim/sumo_simulation.hpp"

using namespace dualgrid;

namespace {

constexpr int kSteps = 400;  // 20 s of the highway: the truck alongside, overtakers, rails

struct RunTime {
  double seconds = 0.0;
  std::size_t detections = 0, ghosts = 0;
};

RunTime TimeRun(bool multipath, int threads) {
  const std::filesystem::path scenario =
      std::filesystem::path(DUALGRID_SOURCE_DIR) / "scenarios" / "highway.yaml";
  const scenario::ScenarioConfig config = scenario::LoadScenario(
      scenario, {{"sensors.multipath", multipath ? "on" : "off"}, {"duration", "60"}});
  cosim::CoSimulation cs(config, {.modes = {}, .threads = threads});
  const std::filesystem::path work = std::filesystem::temp_directory_path() / "bench_sim_step";
  std::filesystem::create_directories(work);
  cs.Start(sim::DefaultNetworkDir(), work);
  RunTime t;
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  for (int i = 0; i < kSteps && cs.Step(); ++i) {
    for (const radar::Detection& d : cs.pipeline().detections())
      t.ghosts += d.path != radar::Path::kDirect;
    t.detections += cs.pipeline().detections().size();
  }
  t.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  return t;
}

void BM_SimStepMultipath(benchmark::State& state) {
  const int threads = static_cast<int>(state.range(0));
  omp_set_num_threads(threads);
  double off_s = 0.0, on_s = 0.0;
  std::size_t ghosts = 0, detections = 0, iteration = 0;
  for (auto _ : state) {
    // Alternate the order, so that a drifting load hits both alike.
    RunTime off, on;
    if (iteration++ % 2 == 0) {
      off = TimeRun(false, threads);
      on = TimeRun(true, threads);
    } else {
      on = TimeRun(true, threads);
      off = TimeRun(false, threads);
    }
    off_s += off.seconds;
    on_s += on.seconds;
    ghosts = on.ghosts;
    detections = off.detections;
  }
  const double steps = static_cast<double>(state.iterations()) * kSteps;
  state.counters["off_ms_per_step"] = 1e3 * off_s / steps;
  state.counters["on_ms_per_step"] = 1e3 * on_s / steps;
  state.counters["ratio"] = on_s / off_s;
  state.counters["detections_per_step"] = static_cast<double>(detections) / kSteps;
  state.counters["ghosts_per_step"] = static_cast<double>(ghosts) / kSteps;
}
BENCHMARK(BM_SimStepMultipath)
    ->Arg(1)
    ->Arg(2)
    ->Iterations(4)
    ->Unit(benchmark::kSecond)
    ->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
