// The floor of issue 37's end-to-end rows, measured on the rows' own inputs: for every step of a
// run, the source's step (SUMO and the radar scan, or a recorded scan) as it runs in dualgrid,
// then one FloorCycle (floor_cycle.hpp: a cycle's least work in the new design) on that step's
// measurements and fields of view, on one thread. Three modes share the measurement grid and
// each runs the rest of the cycle, so a step's least CPU work is
//   source + measurement grid + 3 x (prediction + sort + cells + births + resampling).
// Scoring, the run's files and figures are left out (work the rows also do): the ceiling below
// is an upper bound on what the row can reach, assuming both cores busy all the time.
// Arguments: 0 = the highway scenario (60 s, the no-figures row), 1 = the recorded sequence of
// bench_recorded (20 s, 1 ms window). Counters per step [ms of CPU]: source, mgrid, modes3;
// ceiling_x_real_time = simulated seconds / ((source + mgrid + modes3) / 2 cores).
//   bench_floor_e2e --benchmark_filter=FloorE2E
#include <benchmark/benchmark.h>

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <omp.h>

#include "dualgrid/cosim/cosimulation.hpp"
#include "dualgrid/cosim/recorded_source.hpp"
#include "dualgrid/scenario/loader.hpp"
#include "dualgrid/sim/sumo_simulation.hpp"
#include "floor_cycle.hpp"
#include "pipeline_inputs.hpp"
#include "recorded_sequence.hpp"

using namespace dualgrid;

namespace {

struct Totals {
  double source = 0.0, mgrid = 0.0, rest = 0.0, simulated = 0.0;
  std::int64_t steps = 0, detections = 0;
};

// Runs `cs` (no filters) to its end, one FloorCycle per step on its inputs.
void RunFloor(cosim::CoSimulation& cs, const filter::FilterParams& fp, double dt, Totals& t) {
  omp_set_num_threads(1);
  bench::FloorCycle floor(fp.num_particles, fp.num_birth, fp.CellsX(), fp.CellsY(), fp.resolution,
                          1);
  std::vector<filter::Measurement> z;
  std::vector<filter::SensorCoverage> coverage;
  Position centre;
  for (;;) {
    const double c0 = bench::ProcessCpu();
    if (!cs.Step()) break;
    t.source += bench::ProcessCpu() - c0;
    bench::PipelineInputs(cs.pipeline(), &z, &coverage, &centre);
    floor.Run(centre, z, coverage, dt);
    t.detections += static_cast<std::int64_t>(z.size());
    ++t.steps;
  }
  const auto& ph = floor.PhaseCpu();
  t.mgrid += ph[0];
  t.rest += ph[1] + ph[2] + ph[3] + ph[4] + ph[5];
}

void BM_FloorE2E(benchmark::State& state) {
  const bool recorded = state.range(0) == 1;
  Totals t;
  const cosim::RecordedSequence seq = recorded ? bench::MakeSequence() : cosim::RecordedSequence{};
  for (auto _ : state) {
    if (recorded) {
      scenario::ScenarioConfig config = cosim::DefaultRecordedConfig();
      const cosim::RecordedOptions o = cosim::FitConfig(seq, 1e-3, &config);
      cosim::CoSimulation cs(config, {.modes = {}, .threads = 1},
                             [&](const scenario::ScenarioConfig&, cosim::IdRegistry&) {
                               return std::make_unique<cosim::RecordedSource>(seq, o);
                             });
      cs.Start({}, {});
      // A cycle per scan: dt is the scans' mean spacing (the floor's cost does not depend on it).
      RunFloor(cs, config.filter, 0.01875, t);
      t.simulated += config.sim.duration;
    } else {
      const std::filesystem::path scenario =
          std::filesystem::path(DUALGRID_SOURCE_DIR) / "scenarios" / "highway.yaml";
      const scenario::ScenarioConfig config = scenario::LoadScenario(scenario, {});
      cosim::CoSimulation cs(config, {.modes = {}, .threads = 1});
      const std::filesystem::path work = std::filesystem::temp_directory_path() / "bench_floor";
      std::filesystem::create_directories(work);
      cs.Start(sim::DefaultNetworkDir(), work);
      RunFloor(cs, config.filter, config.sim.step_length, t);
      t.simulated += config.sim.duration;
    }
  }
  const double steps = static_cast<double>(t.steps);
  state.counters["source_ms"] = 1e3 * t.source / steps;
  state.counters["mgrid_ms"] = 1e3 * t.mgrid / steps;
  state.counters["modes3_ms"] = 3e3 * t.rest / steps;
  state.counters["detections"] = static_cast<double>(t.detections) / steps;
  state.counters["ceiling_x_real_time"] = t.simulated / ((t.source + t.mgrid + 3.0 * t.rest) / 2.0);
}
BENCHMARK(BM_FloorE2E)->Arg(0)->Arg(1)->Iterations(1)->Unit(benchmark::kSecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
