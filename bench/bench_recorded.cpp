// Issue 23's speed target: a recorded sequence is filtered at least 10x faster than real time.
// Every iteration reads a RadarScenes sequence from disk (written once by our writer: 20 s, four
// radars at ~13.3 Hz each, about 50 detections per scan, as the published data average) and runs
// `dualgrid filter`'s loop on it (RecordedSource -> every mode's filter cycle -> scoring, the
// default recorded grid of 100 m x 60 m and 10,000 particles), without the run folder's files.
// Counter x_real_time = sequence seconds per wall second. Arguments: the number of modes (1: dual
// alone, 3: position, velocity, dual) and the batch window [ms] (1: a cycle per scan, the
// default; 70: the four radars' scans of one ~75 ms round in one cycle), side by side in one run.
//   OMP_NUM_THREADS=1 bench_recorded --benchmark_filter=Recorded
// The end-to-end command (files, figures, replay) is timed in docs/performance.md.
#include <benchmark/benchmark.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <memory>

#include "dualgrid/cosim/cosimulation.hpp"
#include "dualgrid/cosim/recorded_source.hpp"
#include "dualgrid/recorded/radarscenes.hpp"
#include "dualgrid/recorded/recorded_run.hpp"
#include "recorded_sequence.hpp"

using namespace dualgrid;

namespace {

std::filesystem::path SequenceDir() {
  static const std::filesystem::path root = [] {
    const auto r = std::filesystem::temp_directory_path() / "bench_recorded";
    std::filesystem::remove_all(r);
    recorded::WriteRadarScenes(bench::MakeSequence(), r, 1.45);
    return r;
  }();
  return root / "data" / "sequence_bench";
}

void BM_Recorded(benchmark::State& state) {
  const auto dir = SequenceDir();
  std::vector<filter::WeightMode> modes = {filter::WeightMode::kDual};
  if (state.range(0) == 3)
    modes = {filter::WeightMode::kPosition, filter::WeightMode::kVelocity,
             filter::WeightMode::kDual};
  double seconds = 0.0;
  int cycles = 0;
  for (auto _ : state) {
    const cosim::RecordedSequence seq = recorded::ReadRadarScenes(dir, std::nullopt);
    scenario::ScenarioConfig config = cosim::DefaultRecordedConfig();
    const cosim::RecordedOptions o =
        cosim::FitConfig(seq, 1e-3 * static_cast<double>(state.range(1)), &config);
    cosim::CoSimulation cs(config, {modes, 0},
                           [&](const scenario::ScenarioConfig&, cosim::IdRegistry&) {
                             return std::make_unique<cosim::RecordedSource>(seq, o);
                           });
    cs.Start({}, {});
    while (cs.Step()) {
    }
    seconds += config.sim.duration;
    cycles = cs.steps();
  }
  state.counters["x_real_time"] = benchmark::Counter(seconds, benchmark::Counter::kIsRate);
  state.counters["cycles"] = cycles;
}

}  // namespace

BENCHMARK(BM_Recorded)
    ->Args({1, 1})
    ->Args({3, 1})
    ->Args({1, 70})
    ->Args({3, 70})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

BENCHMARK_MAIN();
