// MeasurementGrid::Build (step 4: nearest detections, field of view and ray free space, the
// Doppler fit) on the highway scenario's own inputs: every step of the 60 s run (~500 detections,
// five radars) is captured once (SUMO and the radar model), then each benchmark iteration builds
// the grid of every captured step in order, as the co-simulation does.
// Arguments: threads (OpenMP), fit (1: birth_velocity doppler_fit and velocity_likelihood
// radial_fit, the defaults; 0: both off, the fit skipped). Counters per step: build_us (wall),
// cpu_us (process CPU), detections. Results: docs/performance.md.
//   bench_measurement_grid --benchmark_filter=MeasurementGrid
#include <benchmark/benchmark.h>

#include <chrono>
#include <filesystem>
#include <vector>

#include <omp.h>

#include "dualgrid/cosim/cosimulation.hpp"
#include "dualgrid/filter/measurement_grid.hpp"
#include "dualgrid/scenario/loader.hpp"
#include "dualgrid/sim/sumo_simulation.hpp"
#include "pipeline_inputs.hpp"

using namespace dualgrid;

namespace {

struct StepInputs {
  std::vector<filter::Measurement> z;
  std::vector<filter::SensorCoverage> coverage;
  Position centre;
};

struct Run {
  filter::FilterParams params;
  std::vector<StepInputs> steps;
};

// The highway run's inputs, captured at the first call (no filters run).
const Run& Highway() {
  static const Run run = [] {
    const std::filesystem::path scenario =
        std::filesystem::path(DUALGRID_SOURCE_DIR) / "scenarios" / "highway.yaml";
    const scenario::ScenarioConfig config = scenario::LoadScenario(scenario, {});
    cosim::CoSimulation cs(config, {.modes = {}, .threads = 1});
    const std::filesystem::path work = std::filesystem::temp_directory_path() / "bench_mgrid";
    std::filesystem::create_directories(work);
    cs.Start(sim::DefaultNetworkDir(), work);
    Run r;
    r.params = config.filter;
    while (cs.Step()) {
      StepInputs s;
      bench::PipelineInputs(cs.pipeline(), &s.z, &s.coverage, &s.centre);
      r.steps.push_back(std::move(s));
    }
    return r;
  }();
  return run;
}

void BM_MeasurementGrid(benchmark::State& state) {
  const Run& run = Highway();
  omp_set_num_threads(static_cast<int>(state.range(0)));
  filter::FilterParams fp = run.params;
  if (state.range(1) == 0) {
    fp.birth_velocity = filter::BirthVelocity::kUniform;
    fp.velocity_likelihood = filter::VelocityLikelihood::kVector;
  }
  filter::MeasurementGrid grid(fp);
  for (const StepInputs& s : run.steps) grid.Build(s.centre, s.z, s.coverage);  // warm-up
  double cpu = 0.0, wall = 0.0;
  for (auto _ : state) {
    const double c0 = bench::ProcessCpu();
    const auto w0 = std::chrono::steady_clock::now();
    for (const StepInputs& s : run.steps) grid.Build(s.centre, s.z, s.coverage);
    wall += std::chrono::duration<double>(std::chrono::steady_clock::now() - w0).count();
    cpu += bench::ProcessCpu() - c0;
  }
  std::int64_t detections = 0;
  for (const StepInputs& s : run.steps) detections += static_cast<std::int64_t>(s.z.size());
  const double builds = static_cast<double>(state.iterations()) * run.steps.size();
  state.counters["build_us"] = 1e6 * wall / builds;
  state.counters["cpu_us"] = 1e6 * cpu / builds;
  state.counters["detections"] = static_cast<double>(detections) / run.steps.size();
  state.SetItemsProcessed(static_cast<std::int64_t>(builds));
}
BENCHMARK(BM_MeasurementGrid)
    ->Args({1, 1})
    ->Args({2, 1})
    ->Args({1, 0})
    ->Args({2, 0})
    ->Iterations(3)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
