// The dualgrid subcommands. Each takes its parsed options and returns the process exit code;
// errors are thrown and reported in one line by main().
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "dualgrid/filter/params.hpp"

namespace dualgrid::tools {

/// Options shared by every command that runs a scenario.
struct RunOptions {
  std::filesystem::path scenario;
  std::filesystem::path out;
  std::optional<std::uint64_t> seed;
  std::optional<double> duration;
  std::filesystem::path network_dir;
  bool quiet = false;
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
  std::vector<double> snapshots;  ///< grid picture times [s]; empty: from the scenario
  bool figures = true;
  /// Formats every figure is written in: "png", "svg", "pdf" (`--figure-formats`).
  std::vector<std::string> figure_formats = {"png", "svg", "pdf"};
  /// Captions under the figures (`--figure-captions on|off`; off for a paper that sets its own).
  bool figure_captions = true;
  /// What the figures call the reference objects (figures.hpp, WordsFor): "sumo", "annotated"
  /// (nuScenes) or "tracks" (estimated from labelled points: RadarScenes, run folders).
  std::string references = "sumo";
  /// detections.csv: "none", "csv" or "csv.gz" (gzip-compressed, about 3.5x smaller).
  std::string detections = "none";
  /// figures/particles_<mode>_t<time>.csv beside each grid picture (several MB each).
  bool write_particles = false;
  int threads = 0;  ///< OpenMP threads; 0: the OpenMP default
  /// Checks every filter's invariants after every step (DynamicGrid::CheckInvariants; a
  /// violation ends the run with exit code 1) and samples the resident memory every 60 s
  /// simulated into summary.json (`rss_mb`): the soak test's mode.
  bool check_invariants = false;
  /// The replay recording (RUN_DIR/replay/, docs/replay.md): one frame every `record_interval`
  /// [s] (rounded to whole steps) with up to `record_particles` particles per mode. On with
  /// figures unless `--no-record`.
  bool record = true;
  /// Two frames per simulated second and 500 particles: about 8 MB per simulated minute of the
  /// highway (docs/replay.md, "Cost"); --record-interval 0.1 for every tenth of a second.
  double record_interval = 0.5;
  int record_particles = 500;
  /// After the results: the replay video (`--video`) and the interactive viewer (`--viewer`),
  /// as `dualgrid replay` would write them with its defaults.
  bool video = false;
  bool viewer = false;
};

/// `dualgrid replay`: the video and/or the interactive viewer of a recorded run, without SUMO.
struct ReplayOptions {
  std::filesystem::path run_dir;
  bool video = false;              ///< MP4 (H.264) + preview; the default when neither is asked for
  bool html = false;               ///< the self-contained interactive viewer
  std::filesystem::path out;       ///< video file (.mp4); default RUN_DIR/replay.mp4
  std::filesystem::path html_out;  ///< default RUN_DIR/replay.html
  std::vector<std::string> modes;  ///< subset of the recorded modes; empty: all
  bool particles = false;          ///< video: draw the recorded particles
  bool detections = true;          ///< video: draw the detections, coloured per sensor
  double from = 0.0, to = 0.0;     ///< time window [s]; to = 0: to the end
  double speed = 1.0;              ///< video playback speed (1 = real time)
  int width = 1920;                ///< video width [px]
  std::string preview = "gif";     ///< "gif", "webm" or "none"
  bool quiet = false;
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

int RunSim(const SimOptions& options);
int RunSweep(const SweepOptions& options);
int RunCollect(const CollectOptions& options);
int RunRegress(const RegressOptions& options);
int RunTangential(const TangentialOptions& options);
int RunFilters(const FilterRunOptions& options);
int RunReplay(const ReplayOptions& options);
int RunExperiment(const ExperimentOptions& options);
int RunSnapshot(const SnapshotOptions& options);

/// Parses mode names or throws naming the bad one.
std::vector<filter::WeightMode> ParseModes(const std::vector<std::string>& names);

}  // namespace dualgrid::tools
