// run_scenario: one co-simulation (SUMO, radar, the filters of each mode, scoring) through
// dualgrid::cosim, the loop `dualgrid run` drives, with the results as Python dicts and numpy
// columns (pandas.DataFrame(result["clusters"]) takes them as they are).
#include <pybind11/numpy.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "bindings.hpp"
#include "convert.hpp"
#include "dualgrid/cosim/cosimulation.hpp"

namespace dualgrid::python {
namespace {

namespace fs = std::filesystem;

// Every cluster of every step and mode, as clusters.csv holds them (world frame).
struct ClusterColumns : cosim::StepObserver {
  std::vector<int> step;
  std::vector<double> time, x, y, vx, vy, weight;
  std::vector<int> particles;
  std::vector<std::string> mode, role, object;

  void OnStep(const cosim::StepView& v) override {
    static const char* kRole[] = {"matched", "duplicate", "false"};
    const GridFrame& g = v.pipeline.grid_frame();
    for (std::size_t m = 0; m < v.scorers.size(); ++m) {
      const auto& a = v.scorers[m].association();
      const auto& clusters = v.scorers[m].clusters();
      for (std::size_t c = 0; c < clusters.size(); ++c) {
        const Position p = g.ToWorld(clusters[c].position);
        const Velocity u = g.VectorToWorld(clusters[c].velocity);
        step.push_back(v.frame.step);
        time.push_back(v.frame.time);
        mode.push_back(v.mode_names[m]);
        x.push_back(p.x());
        y.push_back(p.y());
        vx.push_back(u.x());
        vy.push_back(u.y());
        weight.push_back(clusters[c].weight);
        particles.push_back(clusters[c].size);
        role.push_back(kRole[static_cast<int>(a.role[c])]);
        const int o = a.object_of_cluster[c];
        object.push_back(o >= 0 ? v.pipeline.ids().Name(v.objects[o].id) : std::string());
      }
    }
  }
  py::dict Columns() const {
    py::dict d;
    d["step"] = ToArray(step);
    d["time"] = ToArray(time);
    d["mode"] = py::cast(mode);
    d["x"] = ToArray(x);
    d["y"] = ToArray(y);
    d["vx"] = ToArray(vx);
    d["vy"] = ToArray(vy);
    d["weight"] = ToArray(weight);
    d["particles"] = ToArray(particles);
    d["role"] = py::cast(role);
    d["object"] = py::cast(object);
    return d;
  }
};

py::object FromJson(const nlohmann::json& j) {
  return py::module_::import("json").attr("loads")(j.dump());
}

// objects.csv's rows as columns: every key of eval::ObjectMetrics, plus mode and name.
py::dict ObjectColumns(const std::vector<std::string>& modes,
                       const std::vector<eval::ScenarioMetrics>& metrics,
                       const cosim::IdRegistry& ids) {
  std::vector<nlohmann::json> rows;
  for (std::size_t m = 0; m < metrics.size(); ++m)
    for (const eval::ObjectMetrics& o : metrics[m].objects) {
      nlohmann::json row = o;
      row["mode"] = modes[m];
      row["name"] = ids.Name(o.id);
      rows.push_back(std::move(row));
    }
  std::vector<std::string> keys;
  for (const auto& row : rows)
    for (const auto& [k, value] : row.items())
      if (std::find(keys.begin(), keys.end(), k) == keys.end()) keys.push_back(k);
  nlohmann::json columns = nlohmann::json::object();
  for (const auto& k : keys) {
    columns[k] = nlohmann::json::array();
    for (const auto& row : rows) columns[k].push_back(row.contains(k) ? row[k] : nullptr);
  }
  py::dict d;
  for (const auto& [k, value] : FromJson(columns).cast<py::dict>()) d[k] = value;
  return d;
}

py::dict RunScenario(const fs::path& path, std::optional<std::uint64_t> seed,
                     std::optional<double> duration, const std::vector<std::string>& modes,
                     const std::vector<std::string>& overrides, std::optional<fs::path> network_dir,
                     std::optional<fs::path> work_dir, int threads) {
  std::vector<scenario::Override> sets;
  for (const std::string& s : overrides) sets.push_back(scenario::ParseOverride(s));
  scenario::ScenarioConfig config = scenario::LoadScenario(path, sets);
  if (seed) config.sim.seed = *seed;
  if (duration) {
    if (!(*duration > 0.0 && *duration <= 3600.0))
      throw py::value_error("run_scenario: duration must be in (0, 3600] s, got " +
                            std::to_string(*duration));
    config.sim.duration = *duration;
  }
  cosim::CoSimOptions options;
  options.modes.clear();
  for (const std::string& name : modes) {
    const auto m = filter::ParseWeightMode(name);
    if (!m)
      throw py::value_error("run_scenario: modes: unknown mode '" + name +
                            "' (expected position, velocity, dual)");
    options.modes.push_back(*m);
  }
  if (options.modes.empty()) throw py::value_error("run_scenario: modes must not be empty");
  if (threads < 0) throw py::value_error("run_scenario: threads must be >= 0");
  options.threads = threads;
  // SUMO's route file and log: the caller's folder, or a temporary one removed afterwards.
  const bool own_work = !work_dir;
  const fs::path work =
      work_dir ? *work_dir
               : fs::temp_directory_path() /
                     ("dualgrid_py_" + std::to_string(getpid()) + "_" + config.sim.name);
  fs::create_directories(work);

  cosim::CoSimulation cs(config, options);
  ClusterColumns clusters;
  {
    py::gil_scoped_release release;  // the run is C++ only; other Python threads go on
    cs.Start(network_dir ? *network_dir : sim::DefaultNetworkDir(), work);
    cs.AddObserver(&clusters);
    while (cs.Step()) {
    }
    cs.Finish();
  }
  if (own_work) {
    std::error_code ec;
    fs::remove_all(work, ec);
  }
  const std::vector<eval::ScenarioMetrics> metrics = cs.Metrics();
  nlohmann::json mj = nlohmann::json::object();
  for (std::size_t m = 0; m < metrics.size(); ++m) mj[cs.mode_names()[m]] = metrics[m];
  nlohmann::json names = nlohmann::json::object();
  if (!metrics.empty())
    for (const auto& o : metrics.front().objects)
      names[std::to_string(o.id)] = cs.pipeline().ids().Name(o.id);

  py::dict r;
  r["scenario"] = config.sim.name;
  r["seed"] = config.sim.seed;
  r["steps"] = cs.steps();
  r["simulated_s"] = cs.simulated();
  r["requested_s"] = config.sim.duration;
  r["complete"] = cs.finished();
  r["detections_per_step"] =
      cs.steps() ? static_cast<double>(cs.total_detections()) / cs.steps() : 0.0;
  r["metrics"] = FromJson(mj);
  r["object_names"] = FromJson(names);
  r["objects"] = ObjectColumns(cs.mode_names(), metrics, cs.pipeline().ids());
  r["clusters"] = clusters.Columns();
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
