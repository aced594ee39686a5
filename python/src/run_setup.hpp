// Configuration of a co-simulation from Python arguments, shared by run_scenario / run_recorded
// and the step-by-step CoSimulation / RecordedSimulation (stepping_bindings.cpp): the same
// arguments give the same configuration, so the two ways give the same numbers.
#pragma once

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "bindings.hpp"
#include "convert.hpp"
#include "dualgrid/cosim/cosimulation.hpp"
#include "dualgrid/cosim/recorded_source.hpp"
#include "dualgrid/recorded/recorded_run.hpp"

namespace dualgrid::python {

/// A scenario file with the caller's seed [-], duration [s] and "KEY=VALUE" overrides. `fn`
/// names the calling function in messages. Throws ValueError (scenario::ConfigError or
/// py::value_error) for bad input.
scenario::ScenarioConfig LoadRunConfig(const std::filesystem::path& path, std::optional<Seed> seed,
                                       std::optional<double> duration,
                                       const std::vector<std::string>& overrides, const char* fn);

/// Weight modes by name and the thread count [-] as CoSimOptions; ValueError naming `fn`.
cosim::CoSimOptions RunOptions(const std::vector<std::string>& modes, int threads, const char* fn);

/// A recorded input read and fitted (recorded::ReadRecordedInput, FitConfig): the configuration
/// (a scenario file's keys, or the recorded defaults) and the source options.
struct RecordedSetup {
  recorded::RecordedInput input;
  scenario::ScenarioConfig config;
  cosim::RecordedOptions options;
};
RecordedSetup LoadRecorded(const std::filesystem::path& path,
                           const std::optional<std::filesystem::path>& sensors,
                           const std::optional<std::filesystem::path>& scenario_file,
                           const std::vector<std::string>& overrides, std::optional<Seed> seed,
                           double batch_window, const char* fn);

/// The "input" entry of run_recorded's result (kind, sequence, scans, detections, ...).
py::dict RecordedInputInfo(const recorded::RecordedInput& in);

/// The networks folder: `given`, else $DUALGRID_NETWORK_DIR, else the installed package's
/// (dualgrid.installed_network_dir()), else the build tree's (sim::DefaultNetworkDir()).
std::filesystem::path NetworkDir(const std::optional<std::filesystem::path>& given);

/// libsumo is one per process: a SUMO co-simulation holds this while it runs. Acquire() throws
/// RuntimeError naming `who` when another holds it.
class SumoClaim {
 public:
  explicit SumoClaim(const char* who);
  ~SumoClaim() { Release(); }
  SumoClaim(const SumoClaim&) = delete;
  SumoClaim& operator=(const SumoClaim&) = delete;
  void Release();

 private:
  bool held_ = false;
};

/// SUMO's work folder: the caller's, or a fresh temporary one removed by Remove().
struct WorkDir {
  std::filesystem::path path;
  bool owned = false;
  /// `given` (which may not equal, contain or lie inside a file `config` reads: ValueError), or a
  /// new temporary folder named after the scenario.
  static WorkDir Make(const std::optional<std::filesystem::path>& given,
                      const scenario::ScenarioConfig& config,
                      const std::filesystem::path& network_dir);
  void Remove();
};

}  // namespace dualgrid::python
