// A user's program: the filter on its own, the recorded-data library (HDF5 linked), then a short
// co-simulation through dualgrid::cosim, and a run folder through dualgrid::outputs. Prints
// "filter ok", "recorded ok", "networks=DIR (SOURCE)", then one line per mode "MODE objects=N
// matches=M", "steps=N of M", then "run folder ok".
#include <cstdio>
#include <filesystem>

#include "dualgrid/cosim/cosimulation.hpp"
#include "dualgrid/filter/dynamic_grid.hpp"
#include "dualgrid/outputs/run.hpp"
#include "dualgrid/recorded/radarscenes.hpp"

using namespace dualgrid;

// A short co-simulation of `config`: prints each mode's scores and the steps; true when it
// reached its duration.
bool Run(const scenario::ScenarioConfig& config) {
  cosim::CoSimulation cs(config);
  const auto work = std::filesystem::temp_directory_path() / "dualgrid_consumer";
  std::filesystem::create_directories(work);
  cs.Start(NETWORK_DIR, work);
  while (cs.Step()) {
  }
  const auto metrics = cs.Metrics();
  for (std::size_t m = 0; m < metrics.size(); ++m)
    std::printf("%s objects=%d matches=%lld\n", cs.mode_names()[m].c_str(),
                metrics[m].objects_scored, static_cast<long long>(metrics[m].matches));
  std::printf("steps=%d of %d\n", cs.steps(), cs.config().sim.StepCount());
  return cs.finished();
}

int main() {
  // The filter alone: one empty cycle leaves every cell unknown or free, none dynamic.
  filter::DynamicGrid grid(*filter::Preset("paper"), 1);
  grid.Update({Pose2{}, Velocity::Zero()}, {}, {}, 0.05);
  if (grid.cells_x() != 400 || grid.cells_y() != 50) return 1;
  std::printf("filter ok\n");
  // A missing sequence is reported (through the HDF5-linked reader), not a crash.
  try {
    recorded::ReadRadarScenes("/nonexistent/data/sequence_1", std::nullopt);
    return 1;
  } catch (const std::invalid_argument&) {
  }
  if (recorded::LabelOfVClass("truck") != 2) return 1;
  std::printf("recorded ok\n");

  // The package's networks by default (never the build tree it was built in).
  const sim::NetworkDirLocation networks = sim::FindNetworkDir({}, sim::DefaultNetworkDir());
  std::printf("networks=%s (%s)\n", sim::DefaultNetworkDir().c_str(), networks.source.c_str());

  auto config = scenario::LoadScenario(std::string(SCENARIO_DIR) + "/highway.yaml");
  config.sim.duration = 3.0;
  if (!Run(config)) return 1;

  // The run folder as `dualgrid run --no-figures` writes it (libsumo: one simulation per process
  // at a time, the first one is gone).
  config.sim.duration = 1.0;
  const auto work = std::filesystem::temp_directory_path() / "dualgrid_consumer";
  cosim::CoSimulation run(config, {.modes = {filter::WeightMode::kDual}});
  outputs::RunFolderOptions o;
  o.out = work / "run";
  o.network_dir = sim::DefaultNetworkDir();
  o.figures = o.record = false;
  o.quiet = true;
  o.force = true;  // the test's own temporary folder, written again by every run of the test
  const outputs::RunFolderResult r = outputs::WriteRunFolder(run, config, o);
  if (!r.complete || !std::filesystem::exists(o.out / "summary.json")) return 1;
  std::printf("run folder ok\n");
  return 0;
}
