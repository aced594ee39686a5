// run_scenario: one co-simulation (SUMO, radar, the filters of each mode, scoring) through
// dualgrid::cosim, the loop `dualgrid run` drives, with the results as Python dicts and numpy
// columns (pandas.DataFrame(result["clusters"]) takes them as they are).
#include <pybind11/numpy.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <algorithm>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "bindings.hpp"
#include "convert.hpp"
#include "dualgrid/cosim/cosimulation.hpp"
#include "dualgrid/outputs/run.hpp"
#include "dualgrid/outputs/run_config.hpp"
#include "run_results.hpp"
#include "run_setup.hpp"

namespace dualgrid::python {
namespace {

namespace fs = std::filesystem;

// SUMO's route file and log go to `work_dir`, or a temporary folder removed afterwards.
void RunToEnd(cosim::CoSimulation& cs, const fs::path& network_dir,
              const std::optional<fs::path>& work_dir) {
  WorkDir work = WorkDir::Make(work_dir, cs.config(), network_dir);
  {
    py::gil_scoped_release release;  // the run is C++ only; other Python threads go on
    cs.Start(network_dir, work.path);
    while (cs.Step()) {
    }
    cs.Finish();
  }
  work.Remove();
}

// The run folder `out`, as `dualgrid run` writes it with its default options (`threads` 1: the
// outputs in line, as `--threads 1`).
void RunToFolder(cosim::CoSimulation& cs, const scenario::ScenarioConfig& config,
                 const fs::path& network_dir, const fs::path& out, bool force, int threads) {
  outputs::RunFolderOptions folder;
  folder.out = out;
  folder.force = force;
  folder.out_option = "run_scenario: out";
  folder.force_flag = "force=True";
  folder.network_dir = network_dir;
  folder.quiet = true;
  folder.output_thread = threads != 1;
  py::gil_scoped_release release;
  outputs::WriteRunFolder(cs, config, folder);
}

py::dict RunScenario(const fs::path& path, std::optional<Seed> seed, std::optional<double> duration,
                     const std::vector<std::string>& modes,
                     const std::vector<std::string>& overrides, std::optional<fs::path> network_dir,
                     std::optional<fs::path> work_dir, int threads, std::optional<fs::path> out,
                     bool force) {
  const scenario::ScenarioConfig config =
      LoadRunConfig(path, seed, duration, overrides, "run_scenario");
  const cosim::CoSimOptions options = RunOptions(modes, threads, "run_scenario");
  if (out && work_dir)
    throw py::value_error("run_scenario: work_dir: not with out (SUMO's files go there)");
  SumoClaim sumo("run_scenario");
  cosim::CoSimulation cs(config, options);
  ClusterColumns clusters;
  cs.AddObserver(&clusters);
  const fs::path networks = NetworkDir(network_dir);
  if (out)
    RunToFolder(cs, config, networks, *out, force, threads);
  else
    RunToEnd(cs, networks, work_dir);
  return Results(cs, config, clusters);
}

// `text` as valid UTF-8 (Python's exception text must be): each byte of an invalid sequence
// becomes '?'. A message may quote a file's bytes, and those may be anything.
std::string ValidUtf8(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (std::size_t i = 0; i < text.size();) {
    const auto c = static_cast<unsigned char>(text[i]);
    const std::size_t n = c < 0x80           ? 1
                          : (c >> 5) == 0x6  ? 2
                          : (c >> 4) == 0xe  ? 3
                          : (c >> 3) == 0x1e ? 4
                                             : 0;
    bool ok = n > 0 && i + n <= text.size();
    for (std::size_t k = 1; ok && k < n; ++k)
      ok = (static_cast<unsigned char>(text[i + k]) >> 6) == 0x2;
    if (ok) {
      out.append(text, i, n);
      i += n;
    } else {
      out += '?';
      ++i;
    }
  }
  return out;
}

}  // namespace

void BindCosim(py::module_& m) {
  // A bad scenario file or key, or a bad input file, is the caller's input: ValueError, with the
  // loader's or reader's one line (valid UTF-8: it may quote the file's bytes).
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const scenario::ConfigError& e) {
      PyErr_SetString(PyExc_ValueError, ValidUtf8(e.what()).c_str());
    } catch (const std::invalid_argument& e) {
      PyErr_SetString(PyExc_ValueError, ValidUtf8(e.what()).c_str());
    }
  });
  m.def("run_scenario", &RunScenario, py::arg("path"), py::arg("seed") = py::none(),
        py::arg("duration") = py::none(),
        py::arg("modes") = std::vector<std::string>{"position", "velocity", "dual"},
        py::arg("overrides") = std::vector<std::string>{}, py::arg("network_dir") = py::none(),
        py::arg("work_dir") = py::none(), py::arg("threads") = 0, py::arg("out") = py::none(),
        py::arg("force") = false,
        R"doc(Runs a scenario file as `dualgrid run` does (SUMO, radar, one filter per mode, the
paper's scoring) and returns its results; the same scenario and seed give the CLI's numbers.

path: scenario YAML file. seed, duration [s]: override the file's. modes: weight modes run side
by side on the same detections. overrides: "KEY=VALUE" texts as `--set` (e.g.
"filter.preset=paper"). network_dir: folder of the built networks (default: the installed or
build tree's, or $DUALGRID_NETWORK_DIR). work_dir: where SUMO's route file and sumo.log go
(default: a temporary folder, removed). threads: OpenMP threads (0: default; results do not
depend on it). out: a folder to write the run folder to, as `dualgrid run --out DIR` with its
default options does (metrics, tables, CSV files, figures, the replay recording, summary.json
last; the same bytes as the command line's except the wall-clock times of summary.json; SUMO's
files go there too, so not with work_dir). out must not exist or be empty, or, with force, hold
an earlier dualgrid output (only its own files are removed, as `--force`); out and work_dir may
not equal, contain or lie inside a file the run reads. One run at a time per process (libsumo).

Returns a dict: scenario, seed, steps, simulated_s, requested_s, complete (False when the ego
left the network early), detections_per_step, metrics ({mode: metrics.json's entry}),
object_names ({id: SUMO id}), objects (columns of objects.csv's rows: mode, name, id, ...), and
clusters (numpy columns of clusters.csv, world frame: step, time [s], mode, x, y [m], vx, vy [m/s],
weight, particles, role, object). Raises ValueError for bad input (scenario::ConfigError text
names the file and key), RuntimeError for a SUMO error.)doc");
}

}  // namespace dualgrid::python
