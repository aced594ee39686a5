// run_recorded: the filters of each mode on a recorded sequence (a RadarScenes sequence folder
// or a run folder recorded with --detections exact), as `dualgrid filter` runs them; the same
// result dict as run_scenario.
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "bindings.hpp"
#include "dualgrid/recorded/recorded_run.hpp"
#include "run_results.hpp"
#include "run_setup.hpp"

namespace dualgrid::python {
namespace {

namespace fs = std::filesystem;

py::dict RunRecorded(const fs::path& path, std::optional<fs::path> sensors,
                     std::optional<fs::path> scenario_file,
                     const std::vector<std::string>& overrides, std::optional<std::uint64_t> seed,
                     const std::vector<std::string>& modes, double batch_window, int threads) {
  const RecordedSetup setup =
      LoadRecorded(path, sensors, scenario_file, overrides, seed, batch_window, "run_recorded");
  const cosim::CoSimOptions options = RunOptions(modes, threads, "run_recorded");
  cosim::CoSimulation cs(
      setup.config, options, [&](const scenario::ScenarioConfig&, cosim::IdRegistry&) {
        return std::make_unique<cosim::RecordedSource>(setup.input.sequence, setup.options);
      });
  ClusterColumns clusters;
  {
    py::gil_scoped_release release;
    cs.Start({}, {});
    cs.AddObserver(&clusters);
    while (cs.Step()) {
    }
    cs.Finish();
  }
  py::dict r = Results(cs, setup.config, clusters);
  r["input"] = RecordedInputInfo(setup.input);
  return r;
}

}  // namespace

void BindRecorded(py::module_& m) {
  m.def("run_recorded", &RunRecorded, py::arg("path"), py::arg("sensors") = py::none(),
        py::arg("scenario") = py::none(), py::arg("overrides") = std::vector<std::string>{},
        py::arg("seed") = py::none(),
        py::arg("modes") = std::vector<std::string>{"position", "velocity", "dual"},
        py::arg("batch_window") = 0.001, py::arg("threads") = 0,
        R"doc(Runs the filters on recorded detections as `dualgrid filter` does and returns the
results; the same input, scenario and seed give the CLI's numbers (docs/recorded-data.md).

path: a RadarScenes sequence folder (scenes.json, radar_data.h5) or a dualgrid run folder
recorded with --detections exact. sensors: RadarScenes sensors.json (default: the dataset
root's, two folders up). scenario: a scenario file whose filter, grid and evaluation keys to use
(its step is the filter's reference cycle); overrides: "KEY=VALUE" for it. seed: the filters'
seed. modes: weight modes side by side. batch_window [s]: scans this close to a cycle's first
are filtered together. threads: OpenMP threads (results do not depend on it).

Returns run_scenario's dict (metrics per mode, with "points": the point-level precision, recall
and F1 when the data are labelled; objects: per track_id D and D_v; clusters) and "input" (kind,
sequence, scans, detections, skipped_detections, labels, tracks). Raises ValueError for bad
input: the message names the file and the field.)doc");
}

}  // namespace dualgrid::python
