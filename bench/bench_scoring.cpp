// The per-step scoring of the highway run, on the run's own filter states: the highway scenario
// (60 s, the three weight modes) is run once, and at every `kEvery`-th step every mode's grid
// (particles, cells), the frame and the ground-truth objects are kept. Each iteration then scores
// all kept steps as cosim::CoSimulation does per step: per mode TakeSnapshot + ClassifySnapshot
// (on the filter's thread there), once per step TruthClasses, per mode ModeScorer::AddFrame
// (particles of dynamic cells, DBSCAN, association, cell confusion). One thread: in the run the
// scoring runs inside the per-step parallel region, one mode per thread.
// Counters: per_step (the three modes' scoring of one step), particles_per_mode (clustered
// dynamic particles per step and mode), clusters_per_mode.
//   bench_scoring --benchmark_filter=ScoreStep
// The radar's scan per step: bench_sim_step (SUMO + radar), bench_models --benchmark_filter=Radar.
#include <benchmark/benchmark.h>

#include <filesystem>
#include <string>
#include <vector>

#include <omp.h>

#include "dualgrid/cosim/cosimulation.hpp"
#include "dualgrid/scenario/loader.hpp"
#include "dualgrid/sim/sumo_simulation.hpp"

using namespace dualgrid;

namespace {

constexpr int kEvery = 40;  // every 2 s of the 60 s run: 30 steps kept

// One kept step: every mode's filter state and what the scorer reads besides.
struct KeptStep {
  std::vector<filter::DynamicGrid> grids;
  sim::Frame frame;
  std::vector<eval::TruthObject> objects;
  OrientedBox ego_box;
};

class Keeper : public cosim::StepObserver {
 public:
  std::vector<KeptStep> steps;
  void OnStep(const cosim::StepView& v) override {
    if (v.step % kEvery != kEvery - 1) return;
    KeptStep k{{}, v.frame, v.objects, v.pipeline.grid_frame().ToGrid(v.frame.ego.box)};
    for (std::size_t m = 0; m < v.mode_names.size(); ++m)
      k.grids.push_back(v.pipeline.grid(static_cast<int>(m)));
    steps.push_back(std::move(k));
  }
};

struct Kept {
  scenario::ScenarioConfig config;
  GridFrame grid_frame;  // the last step's (the grid frame is fixed for a SUMO run)
  std::vector<KeptStep> steps;
};

const Kept& KeptRun() {
  static const Kept kept = [] {
    const std::filesystem::path scenario =
        std::filesystem::path(DUALGRID_SOURCE_DIR) / "scenarios" / "highway.yaml";
    Kept k{scenario::LoadScenario(scenario, {}), {}, {}};
    cosim::CoSimulation cs(k.config, {.threads = 2});
    const std::filesystem::path work = std::filesystem::temp_directory_path() / "bench_scoring";
    std::filesystem::create_directories(work);
    cs.Start(sim::DefaultNetworkDir(), work);
    Keeper keeper;
    cs.AddObserver(&keeper);
    while (cs.Step()) {
    }
    k.grid_frame = cs.pipeline().grid_frame();
    k.steps = std::move(keeper.steps);
    return k;
  }();
  return kept;
}

void BM_ScoreStep(benchmark::State& state) {
  const Kept& kept = KeptRun();
  omp_set_num_threads(1);
  const int modes = static_cast<int>(kept.steps.front().grids.size());
  std::vector<cosim::ModeScorer> scorers(modes, cosim::ModeScorer(kept.config.evaluation));
  std::vector<cosim::GridSnapshot> snapshots(modes);
  const double threshold = kept.config.evaluation.dynamic_threshold;
  double time = 0.0;  // the trackers need increasing times
  std::size_t particles = 0, clusters = 0;
  for (auto _ : state) {
    for (const KeptStep& k : kept.steps) {
      time += kept.config.sim.step_length;
      for (int m = 0; m < modes; ++m) {
        cosim::TakeSnapshot(k.grids[m], false, snapshots[m]);
        cosim::ClassifySnapshot(threshold, snapshots[m]);
      }
      const std::vector<std::uint8_t> truth =
          cosim::TruthClasses(snapshots[0], kept.grid_frame, k.frame, kept.config.sim);
      for (int m = 0; m < modes; ++m) {
        scorers[m].AddFrame(time, k.grids[m], snapshots[m], k.objects, truth, k.ego_box);
        clusters += scorers[m].clusters().size();
      }
    }
  }
  for (const KeptStep& k : kept.steps) {
    for (int m = 0; m < modes; ++m) {
      std::vector<eval::WeightedParticle> p;
      cosim::TakeSnapshot(k.grids[m], false, snapshots[m]);
      cosim::ClassifySnapshot(threshold, snapshots[m]);
      cosim::DynamicParticles(k.grids[m], snapshots[m].classes, k.ego_box, &p);
      particles += p.size();
    }
  }
  const double steps = static_cast<double>(state.iterations()) * kept.steps.size();
  state.counters["per_step"] =
      benchmark::Counter(steps, benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
  state.counters["particles_per_mode"] =
      static_cast<double>(particles) / (static_cast<double>(kept.steps.size()) * modes);
  state.counters["clusters_per_mode"] = static_cast<double>(clusters) / (steps * modes);
}
BENCHMARK(BM_ScoreStep)->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime()->MinTime(2.0);

}  // namespace

BENCHMARK_MAIN();
