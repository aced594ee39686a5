// run_scenario: one co-simulation (SUMO, radar, the filters of each mode, scoring) through
// dualgrid::cosim, the loop `dualgrid run` drives, with the results as Python dicts and numpy
// columns (pandas.DataFrame(result["clusters"]) takes them as they are).
#include <pybind11/numpy.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <algorithm>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "bindings.hpp"
#include "convert.hpp"
#include "dualgrid/cosim/cosimulation.hpp"
#include "run_results.hpp"
#include "run_setup.hpp"

namespace dualgrid::python {
namespace {

namespace fs = std::filesystem;

py::dict RunScenario(const fs::path& path, std::optional<std::uint64_t> seed,
                     std::optional<double> duration, const std::vector<std::string>& modes,
                     const std::vector<std::string>& overrides, std::optional<fs::path> network_dir,
                     std::optional<fs::path> work_dir, int threads) {
  const scenario::ScenarioConfig config =
      LoadRunConfig(path, seed, duration, overrides, "run_scenario");
  const cosim::CoSimOptions options = RunOptions(modes, threads, "run_scenario");
  SumoClaim sumo("run_scenario");
  // SUMO's route file and log: the caller's folder, or a temporary one removed afterwards.
  WorkDir work = WorkDir::Make(work_dir, config.sim.name);
  const std::filesystem::path networks = NetworkDir(network_dir);

  cosim::CoSimulation cs(config, options);
  ClusterColumns clusters;
  {
    py::gil_scoped_release release;  // the run is C++ only; other Python threads go on
    cs.Start(networks, work.path);
    cs.AddObserver(&clusters);
    while (cs.Step()) {
    }
    cs.Finish();
  }
  work.Remove();
  py::dict r = Results(cs, config, clusters);
  return r;
}

}  // namespace

void BindCosim(py::module_& m) {
  // A bad scenario file or key is the caller's input: ValueError, with the loader's one line.
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const scenario::ConfigError& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    }
  });
  m.def("run_scenario", &RunScenario, py::arg("path"), py::arg("seed") = py::none(),
        py::arg("duration") = py::none(),
        py::arg("modes") = std::vector<std::string>{"position", "velocity", "dual"},
        py::arg("overrides") = std::vector<std::string>{}, py::arg("network_dir") = py::none(),
        py::arg("work_dir") = py::none(), py::arg("threads") = 0,
        R"doc(Runs a scenario file as `dualgrid run` does (SUMO, radar, one filter per mode, the
paper's scoring) and returns its results; the same scenario and seed give the CLI's numbers.

path: scenario YAML file. seed, duration [s]: override the file's. modes: weight modes run side
by side on the same detections. overrides: "KEY=VALUE" texts as `--set` (e.g.
"filter.preset=paper"). network_dir: folder of the built networks (default: the installed or
build tree's, or $DUALGRID_NETWORK_DIR). work_dir: where SUMO's route file and sumo.log go
(default: a temporary folder, removed). threads: OpenMP threads (0: default; results do not
depend on it). One run at a time per process (libsumo).

Returns a dict: scenario, seed, steps, simulated_s, requested_s, complete (False when the ego
left the network early), detections_per_step, metrics ({mode: metrics.json's entry}),
object_names ({id: SUMO id}), objects (columns of objects.csv's rows: mode, name, id, ...), and
clusters (numpy columns of clusters.csv, world frame: step, time [s], mode, x, y [m], vx, vy [m/s],
weight, particles, role, object). Raises ValueError for bad input (scenario::ConfigError text
names the file and key), RuntimeError for a SUMO error.)doc");
}

}  // namespace dualgrid::python
