// A user's program: the filter on its own, the recorded-data library (HDF5 linked), then a short
// co-simulation through dualgrid::cosim. Prints "filter ok", "recorded ok", then one line per
// mode "MODE objects=N matches=M", then "steps=N of M".
#include <cstdio>
#include <filesystem>

#include "dualgrid/cosim/cosimulation.hpp"
#include "dualgrid/filter/dynamic_grid.hpp"
#include "dualgrid/recorded/radarscenes.hpp"

using namespace dualgrid;

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

  auto config = scenario::LoadScenario(std::string(SCENARIO_DIR) + "/highway.yaml");
  config.sim.duration = 3.0;
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
  return cs.finished() ? 0 : 1;
}
