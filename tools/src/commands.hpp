// The dualgrid subcommands. Each takes its parsed options and returns the process exit code;
// errors are thrown and reported in one line by main().
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "dualgrid/filter/params.hpp"
#include "dualgrid/outputs/run.hpp"
#include "dualgrid/outputs/video.hpp"
#include "dualgrid/scenario/loader.hpp"

namespace dualgrid::tools {

// The command line wires the outputs library (run folders, files, figures, replay): its names are
// used unqualified in the commands.
using namespace outputs;

/// Options shared by every command that runs a scenario.
struct RunOptions {
  std::filesystem::path scenario;
  std::filesystem::path out;
  std::optional<std::uint64_t> seed;
  std::optional<double> duration;
  std::optional<double> begin;  ///< [s, SUMO time] --begin: where SUMO starts
  std::filesystem::path network_dir;
  bool quiet = false;
  bool force = false;  ///< --force: replace an earlier dualgrid output in `out`
  /// `--set KEY=VALUE` overrides of scenario keys, in order (scenario::Override).
  std::vector<std::string> sets;
};

/// `dualgrid sim`: ground truth and radar detections, no filter.
struct SimOptions {
  RunOptions run;
  std::string detections = "csv";  ///< "none", "csv" or "csv.gz"
};

/// `dualgrid run`: the co-simulation with the grid filters, scored against the ground truth.
struct FilterRunOptions {
  RunOptions run;
  std::vector<std::string> modes = {"position", "velocity", "dual"};
  int threads = 0;  ///< OpenMP threads; 0: the OpenMP default
  /// What the run folder holds (figures, detections, recording, ...); its out, network_dir and
  /// quiet are taken from `run` when the command runs (FolderOptions).
  outputs::RunFolderOptions folder;
  /// `folder` with run.out, run.network_dir and run.quiet.
  outputs::RunFolderOptions FolderOptions() const;
};

/// `dualgrid replay`: the video and/or the interactive viewer of a recorded run, without SUMO.
struct ReplayCommandOptions {
  std::filesystem::path run_dir;
  bool video = false;  ///< MP4 (H.264) + preview; the default when neither is asked for
  bool html = false;   ///< the self-contained interactive viewer
  bool quiet = false;
  outputs::ReplayOptions replay;
};

/// `dualgrid experiment`: `run` over seeds 1..N in separate processes, then aggregated.
struct ExperimentOptions {
  FilterRunOptions run;
  int seeds = 10;
  std::uint64_t first_seed = 1;
  int jobs = 0;            ///< parallel runs; 0: number of cores
  std::string executable;  ///< this program, to start the runs
};

/// `dualgrid snapshot`: bird's-eye picture of one time of a scenario.
struct SnapshotOptions {
  RunOptions run;                                          ///< run.out is the PNG to write
  bool figure_captions = true;                             ///< as FilterRunOptions
  double time = 10.0;                                      ///< [s]
  double behind = 60.0, ahead = 140.0, half_width = 22.0;  ///< view around the ego [m]
};

/// `dualgrid tangential`: writes a tangential-motion stress scenario.
struct TangentialOptions {
  /// "crossing" (ahead, across the front radar), "parallel" (alongside), "aspect" (any aspect
  /// angle to any sensor, aspect_case.hpp) or "guardrail" (vehicles passing the ego on the side
  /// away from a guard rail: multipath, guardrail_case.hpp).
  std::string kind = "crossing";
  int count = 4;            ///< stress vehicles
  double ego_speed = 20.0;  ///< [m/s]
  /// Stress vehicles' speed over ground [m/s]; default: crossing 15, parallel ego speed + 0.3.
  std::optional<double> speed;
  double first_distance = 30.0;  ///< crossing: distance ahead of the ego of the first crossing [m]
  /// Crossing: distance between crossings (default 20); parallel: between vehicles of a lane
  /// (default 40) [m].
  std::optional<double> spacing;
  std::uint64_t seed = 1;
  std::filesystem::path out;
  bool force = false;  ///< replace existing files at `out` (and its network files beside it)
  bool quiet = false;
  // kind aspect:
  std::string sensor = "front";
  double angle = 90.0;  ///< [deg]
  double range = 20.0;  ///< [m]
  std::string target = "car";
  double interval = 6.0;  ///< [s]
  /// [m]; unset: the paper's 25 m, widened when a target would not be scored.
  std::optional<double> grid_width;
  // kind guardrail:
  double offset = 3.75;     ///< ego centre line -> rail [m]
  double rail_angle = 0.0;  ///< the rail's aspect to the road [deg]
};

/// `dualgrid regress`.
struct RegressOptions {
  std::filesystem::path suite;
  std::filesystem::path out = "run/regress";
  bool force = false;  ///< --force (implied when --out is not given: the default is ours)
  std::filesystem::path network_dir;
  std::vector<std::string> sets;  ///< --set overrides applied to every case
  std::filesystem::path record;   ///< --record: write the suite with measured bands here
  bool require_digests = false;   ///< a changed digest fails the suite
  int jobs = 0;                   ///< seed runs at a time; 0: one per core
  bool quiet = false;
  std::string executable;
};

/// `dualgrid sweep`.
struct SweepOptions {
  std::string scenario;  ///< a scenario file, or "tangential" (the generator)
  std::filesystem::path out;
  bool force = false;             ///< --force: replace an earlier dualgrid output in `out`
  std::vector<std::string> sets;  ///< KEY=LIST axes (sweep_spec.hpp)
  int seeds = 3;
  std::uint64_t first_seed = 1;
  std::vector<std::string> modes = {"position", "velocity", "dual"};
  std::optional<double> duration;
  int jobs = 0;      ///< local runs at a time; 0: one per core
  std::string emit;  ///< "": run locally; "list": runs.txt only; "slurm": + slurm.sh
  std::filesystem::path network_dir;
  bool quiet = false;
  std::string executable;
  bool figure_captions = true;  ///< of collect's figures, as FilterRunOptions
};
/// `dualgrid collect`.
struct CollectOptions {
  std::filesystem::path dir;
  bool quiet = false;
  bool figure_captions = true;  ///< as FilterRunOptions
};

/// Sets the generator option `key` (a `tangential.KEY` of sweeps and suites, without the
/// prefix) from its text; throws std::invalid_argument naming the key and what was expected.
void SetGeneratorOption(TangentialOptions* o, const std::string& key, const std::string& value);

/// Writes the run folder of `cosim` (outputs::WriteRunFolder) with the terminal's progress and
/// stop signal, prints the table and the one-line result; returns the exit code. `recorded` is
/// null for a SUMO run.
int WriteRunFolderAndReport(cosim::CoSimulation& cosim, const scenario::ScenarioConfig& config,
                            const outputs::RunFolderOptions& folder,
                            const outputs::RecordedRun* recorded);

int RunSim(const SimOptions& options);
int RunSweep(const SweepOptions& options);
int RunCollect(const CollectOptions& options);
int RunRegress(const RegressOptions& options);
int RunTangential(const TangentialOptions& options);
int RunFilters(const FilterRunOptions& options);
int RunReplay(const ReplayCommandOptions& options);
int RunExperiment(const ExperimentOptions& options);
int RunSnapshot(const SnapshotOptions& options);

/// The scenario of `options` with its command-line overrides (outputs::LoadRunConfig).
scenario::ScenarioConfig LoadConfig(const RunOptions& options);

/// Parses mode names or throws naming the bad one.
std::vector<filter::WeightMode> ParseModes(const std::vector<std::string>& names);

}  // namespace dualgrid::tools
