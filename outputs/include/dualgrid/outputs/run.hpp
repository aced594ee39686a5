// A whole run folder (docs/output.md) from a co-simulation, whatever its detection source: the
// files while it runs, then metrics, tables, figures, the replay and, last, summary.json. What
// `dualgrid run` and `dualgrid filter` write, and Python's run_scenario(..., out=DIR).
//
//   auto config = outputs::LoadRunConfig("scenarios/highway.yaml", {}, 1, 20.0);
//   cosim::CoSimulation cs(config, {.modes = {filter::WeightMode::kDual}});
//   outputs::RunFolderOptions o;  o.out = "run/hw";  o.network_dir = sim::DefaultNetworkDir();
//   const outputs::RunFolderResult r = outputs::WriteRunFolder(cs, config, o);
#pragma once

#include <cstddef>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "dualgrid/cosim/cosimulation.hpp"
#include "dualgrid/eval/aggregate.hpp"
#include "dualgrid/outputs/callbacks.hpp"
#include "dualgrid/outputs/output_guard.hpp"

namespace dualgrid::outputs {

/// What goes into a run folder besides the files every run writes. Errors name the command-line
/// option of a field.
struct RunFolderOptions {
  std::filesystem::path out;  ///< the run folder (made ready: PrepareOutputFolder)
  /// Replace an earlier dualgrid output in `out` (its own entries only; output_guard.hpp).
  bool force = false;
  /// How errors name `out` and `force` (the Python module: "run_scenario: out", "force=True").
  std::string out_option = "--out", force_flag = "--force";
  /// What the run reads besides the scenario's files (WriteRunFolder adds those): `out` must lie
  /// apart from all of them (CheckOutputApart), e.g. the recorded data of `dualgrid filter`.
  InputSet inputs;
  std::filesystem::path network_dir;  ///< the built networks, for SUMO (CoSimulation::Start)
  std::vector<double> snapshots;      ///< grid picture times [s]; empty: from the scenario
  bool figures = true;
  /// Formats every figure is written in: "png", "svg", "pdf".
  std::vector<std::string> figure_formats = {"png", "svg", "pdf"};
  bool figure_captions = true;  ///< captions under the figures
  /// What the figures call the reference objects (figures.hpp, WordsFor): "sumo", "annotated"
  /// (a data set's annotated boxes: nuScenes) or "tracks" (estimated from labelled points).
  std::string references = "sumo";
  /// detections.csv: "none", "csv", "csv.gz" (gzip, about 3.5x smaller) or "exact" (17
  /// significant digits, with scans.csv: readable back by dualgrid::recorded).
  std::string detections = "none";
  /// figures/particles_<mode>_t<time>.csv beside each grid picture (several MB each).
  bool write_particles = false;
  /// Checks every filter's invariants after every step (a violation throws std::logic_error)
  /// and samples the resident memory every 60 s simulated into summary.json (`rss_mb`).
  bool check_invariants = false;
  /// The replay recording (RUN_DIR/replay/, docs/replay.md): a frame every `record_interval`
  /// [s] (rounded to whole steps) with up to `record_particles` particles per mode.
  bool record = true;
  double record_interval = 0.5;
  int record_particles = 500;
  /// After the results: the replay video and the viewer page with ReplayOptions' defaults.
  bool video = false;
  bool viewer = false;
  bool quiet = false;  ///< no table on stdout, no notes on stderr (warnings are still printed)
  /// The recording's compression and the step pictures' drawing on one background thread
  /// (OutputWorker), beside the co-simulation's step; false: in line on the calling thread (a run
  /// given one thread, `--threads 1`, stays on one core). The files are the same bytes either way.
  bool output_thread = true;

  /// Throws std::invalid_argument naming the option of the first bad field.
  void Validate() const;
};

/// What `dualgrid filter` adds to a run folder: where its detections came from.
struct RecordedRun {
  nlohmann::json input;    ///< summary.json's `input`: the files, scans, cycles, skips, labels
  bool labels = false;     ///< the data carry labels (point scores and tracks)
  bool annotated = false;  ///< the references are the data set's annotated boxes (nuScenes)
  std::size_t skipped_points = 0;
  std::vector<std::string> notes;  ///< the reader's notes for the table
  /// Annotated data: each reference object's category (objects.csv's last column).
  std::map<std::string, std::string> categories;
};

/// How a run went, once its folder is written.
struct RunFolderResult {
  bool complete = false;  ///< summary.json's `complete`
  int stop = 0;           ///< the non-zero value of Callbacks::stop that stopped it, else 0
  int steps = 0;
  double wall_s = 0.0;
  std::string status;                 ///< why the run is incomplete or short, else ""
  std::vector<std::string> warnings;  ///< figures and replay files that could not be written
  std::string table_markdown;         ///< table.md's text
};

/// The grid picture times of a run: `requested`, else the scenario's within the run, else 1/4,
/// 1/2 and 3/4 of it; sorted and unique. Throws std::invalid_argument naming --snapshots for a
/// requested time outside the run.
std::vector<double> SnapshotTimes(const std::vector<double>& requested,
                                  const scenario::ScenarioConfig& config);

/// Runs `cosim` (not started yet) to its end or until `callbacks.stop` asks, and writes the run
/// folder options.out. `config` is the configuration `cosim` was built with; `recorded` is null
/// for a SUMO run. Throws for bad options (std::invalid_argument) and failed writes of the
/// results (std::runtime_error naming the file); figures and the replay only cost warnings.
RunFolderResult WriteRunFolder(cosim::CoSimulation& cosim, const scenario::ScenarioConfig& config,
                               const RunFolderOptions& options,
                               const RecordedRun* recorded = nullptr,
                               const Callbacks& callbacks = {});

}  // namespace dualgrid::outputs
