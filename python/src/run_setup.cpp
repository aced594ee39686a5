#include "run_setup.hpp"

#include "dualgrid/outputs/output_guard.hpp"
#include "dualgrid/outputs/run_config.hpp"

#include <unistd.h>

#include <atomic>
#include <cstdlib>
#include <memory>
#include <system_error>

namespace dualgrid::python {

namespace fs = std::filesystem;
// DefaultRecordedConfig and FitConfig: in dualgrid::recorded, or in dualgrid::cosim once the
// recorded library no longer needs the scenario (either is found).
using namespace recorded;  // NOLINT(google-build-using-namespace)
using namespace cosim;     // NOLINT(google-build-using-namespace)

scenario::ScenarioConfig LoadRunConfig(const fs::path& path, std::optional<Seed> seed,
                                       std::optional<double> duration,
                                       const std::vector<std::string>& overrides, const char* fn) {
  if (duration && !(*duration > 0.0 && *duration <= 3600.0))
    throw py::value_error(std::string(fn) + ": duration must be in (0, 3600] s, got " +
                          std::to_string(*duration));
  // The command line's loader: the same configuration as `dualgrid run` with these options.
  return outputs::LoadRunConfig(path, overrides, SeedValue(seed), duration);
}

cosim::CoSimOptions RunOptions(const std::vector<std::string>& modes, int threads, const char* fn) {
  cosim::CoSimOptions options;
  options.modes.clear();
  for (const std::string& name : modes) {
    const auto m = filter::ParseWeightMode(name);
    if (!m)
      throw py::value_error(std::string(fn) + ": modes: unknown mode '" + name +
                            "' (expected position, velocity, dual)");
    options.modes.push_back(*m);
  }
  if (options.modes.empty()) throw py::value_error(std::string(fn) + ": modes must not be empty");
  options.threads = CheckThreads(threads, fn, "threads");
  return options;
}

RecordedSetup LoadRecorded(const fs::path& path, const std::optional<fs::path>& sensors,
                           const std::optional<fs::path>& scenario_file,
                           const std::vector<std::string>& overrides, std::optional<Seed> seed,
                           double batch_window, const char* fn) {
  RecordedSetup s;
  if (scenario_file) {
    std::vector<scenario::Override> sets;
    for (const std::string& o : overrides) sets.push_back(scenario::ParseOverride(o));
    s.config = scenario::LoadScenario(*scenario_file, sets);
    s.config.filter.cycle = s.config.sim.step_length;  // its factors are per its step
  } else {
    if (!overrides.empty())
      throw py::value_error(std::string(fn) + ": overrides need a scenario file");
    s.config = DefaultRecordedConfig();
  }
  if (seed) s.config.sim.seed = seed->value;
  if (!(batch_window >= 0.0 && batch_window <= 1.0))
    throw py::value_error(std::string(fn) + ": batch_window must be in [0, 1] s");
  s.input = recorded::ReadRecordedInput(path, sensors);
  s.options = FitConfig(s.input.sequence, batch_window, &s.config);
  return s;
}

py::dict RecordedInputInfo(const recorded::RecordedInput& in) {
  py::dict input;
  input["kind"] = in.radarscenes ? "radarscenes" : "run";
  input["sequence"] = in.sequence.name;
  input["scans"] = in.sequence.scans.size();
  input["detections"] = in.sequence.points.size();
  input["skipped_detections"] = in.sequence.skipped_points;
  input["labels"] = in.sequence.has_labels;
  input["tracks"] = in.sequence.track_names.size();
  return input;
}

fs::path NetworkDir(const std::optional<fs::path>& given) {
  if (given) return *given;
  if (const char* env = std::getenv("DUALGRID_NETWORK_DIR"); env && *env) return env;
  const py::object installed = py::module_::import("dualgrid").attr("installed_network_dir")();
  if (!installed.is_none()) return fs::path(installed.cast<std::string>());
  return sim::DefaultNetworkDir();
}

namespace {
std::atomic<bool> g_sumo_claimed{false};
}  // namespace

SumoClaim::SumoClaim(const char* who) {
  bool expected = false;
  if (!g_sumo_claimed.compare_exchange_strong(expected, true))
    throw std::runtime_error(
        std::string(who) +
        ": another SUMO co-simulation is running in this process (libsumo is one per process): "
        "finish or close() it first, or use another process");
  held_ = true;
}

void SumoClaim::Release() {
  if (held_) g_sumo_claimed = false;
  held_ = false;
}

WorkDir WorkDir::Make(const std::optional<fs::path>& given, const scenario::ScenarioConfig& config,
                      const fs::path& network_dir) {
  const std::string& name = config.sim.name;
  WorkDir w;
  if (given) {
    outputs::InputSet inputs;  // SUMO's route file and log go there: never onto an input
    inputs.AddScenario(config, network_dir);
    outputs::CheckOutputApart(*given, inputs, "work_dir");
    w.path = *given;
  } else {
    static std::atomic<int> counter{0};
    w.path = fs::temp_directory_path() / ("dualgrid_py_" + std::to_string(getpid()) + "_" +
                                          std::to_string(counter++) + "_" + name);
    w.owned = true;
  }
  fs::create_directories(w.path);
  return w;
}

void WorkDir::Remove() {
  if (!owned) return;
  std::error_code ec;
  fs::remove_all(path, ec);
  owned = false;
}

}  // namespace dualgrid::python
