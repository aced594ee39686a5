// `dualgrid run`: one SUMO run, one radar stream, three filters side by side, scored per step.
#include <algorithm>
#include <chrono>
#include <csignal>
#include <iostream>
#include <optional>

#include <nlohmann/json.hpp>

#include "cli_options.hpp"
#include "commands.hpp"
#include "dualgrid/cosim/cosimulation.hpp"
#include "dualgrid/eval/aggregate.hpp"
#include "figures.hpp"
#include "output.hpp"
#include "progress.hpp"
#include "run_loop.hpp"
#include "run_observers.hpp"
#include "run_outputs.hpp"
#include "signals.hpp"
#include "video.hpp"
#include "viewer.hpp"

namespace dualgrid::tools {

std::vector<filter::WeightMode> ParseModes(const std::vector<std::string>& names) {
  std::vector<filter::WeightMode> modes;
  for (const std::string& n : names) {
    const auto m = filter::ParseWeightMode(n);
    if (!m)
      throw std::invalid_argument("unknown mode '" + n + "' (expected position, velocity, dual)");
    if (std::find(modes.begin(), modes.end(), *m) != modes.end())
      throw std::invalid_argument("mode '" + n + "' given twice");
    modes.push_back(*m);
  }
  if (modes.empty()) throw std::invalid_argument("--modes needs at least one mode");
  return modes;
}

namespace {

// Everything the run actually used, so any result can be rerun or compared.
nlohmann::json ConfigJson(const scenario::ScenarioConfig& c, const FilterRunOptions& o) {
  nlohmann::json j = scenario::ConfigToJson(c);
  j["modes"] = o.modes;
  return j;
}

// The grid picture times: the command line's, else the scenario's within the run, else 1/4, 1/2
// and 3/4 of it; sorted and unique. Times asked for on the command line must lie in the run.
std::vector<double> SnapshotTimes(const FilterRunOptions& options,
                                  const scenario::ScenarioConfig& config) {
  std::vector<double> times = options.snapshots;
  if (times.empty())
    for (double t : config.evaluation.snapshot_times)
      if (t > 0.0 && t <= config.sim.duration) times.push_back(t);
  if (times.empty())
    for (double f : {0.25, 0.5, 0.75}) times.push_back(f * config.sim.duration);
  std::sort(times.begin(), times.end());
  times.erase(std::unique(times.begin(), times.end()), times.end());
  for (double t : times)
    if (!(t > 0.0 && t <= config.sim.duration))
      throw std::invalid_argument("--snapshots: time " + FormatFixed(t, 2) +
                                  " s is outside the run (0, " +
                                  FormatFixed(config.sim.duration, 2) + "] s");
  return times;
}

}  // namespace

int RunFilters(const FilterRunOptions& options) {
  const std::vector<filter::WeightMode> modes = ParseModes(options.modes);
  scenario::ScenarioConfig config = LoadConfig(options.run);
  SnapshotTimes(options, config);                      // bad --snapshots: before SUMO
  DetectionPath(options.run.out, options.detections);  // and before the filters' memory
  // Validates (memory, sensors) before anything is written; SUMO starts below.
  cosim::CoSimulation cosim(config, {modes, options.threads});
  return RunLoop(cosim, config, options, nullptr);
}

int RunLoop(cosim::CoSimulation& cosim, const scenario::ScenarioConfig& config,
            const FilterRunOptions& options, const RecordedRun* recorded_run) {
  const std::vector<filter::WeightMode> modes = ParseModes(options.modes);
  const std::vector<double> snapshot_times = SnapshotTimes(options, config);
  const auto detections_path = DetectionPath(options.run.out, options.detections);
  const std::vector<std::string>& mode_names = cosim.mode_names();
  const auto& out = options.run.out;
  PrepareOutputFolder(out);
  std::filesystem::create_directories(out / "figures");
  if (!recorded_run || !config.file.empty()) CopyScenario(config, out);
  WriteTextFile(out / "config.json", ConfigJson(config, options).dump(2) + "\n");

  const auto wall_start = std::chrono::steady_clock::now();
  cosim.Start(options.run.network_dir, out);
  NoteAutoEgo(cosim.pipeline(), options.run.quiet);
  std::vector<std::string> warnings;  // figures and recordings that could not be written
  // Weight traces (paper Fig. 4) of the dual filter, or of the last mode if dual is not run.
  const auto dual = std::find(modes.begin(), modes.end(), filter::WeightMode::kDual);
  const std::size_t trace_mode = dual != modes.end() ? dual - modes.begin() : modes.size() - 1;
  RunFilesObserver files(out, detections_path, config.radar.options.multipath.enabled, trace_mode,
                         config.evaluation.focus_object, ExactDetections(options.detections));
  cosim.AddObserver(&files);
  std::optional<RecordingObserver> recording;
  if (options.record) {
    recording.emplace(out, config, options.record_interval, options.record_particles, &warnings);
    cosim.AddObserver(&*recording);
  }
  std::optional<InvariantObserver> invariants;
  if (options.check_invariants) {
    invariants.emplace(config.sim.step_length);
    cosim.AddObserver(&*invariants);
  }
  PictureObserver pictures(out, snapshot_times, options, &warnings);
  cosim.AddObserver(&pictures);

  Progress progress((recorded_run ? "filter " : "run ") + config.sim.name + " seed " +
                        std::to_string(config.sim.seed),
                    config.sim.StepCount(), !options.run.quiet);
  while (!StopSignal() && cosim.Step())
    progress.Update(cosim.steps(), "t=" + FormatFixed(cosim.pipeline().frame().time, 1) + " s");
  progress.Finish();
  cosim.Finish();
  const int stop = StopSignal();
  const int steps = cosim.steps();
  const double simulated = cosim.simulated();
  const cosim::IdRegistry& ids = cosim.pipeline().ids();
  std::string status;
  const nlohmann::json end = EndRecord(cosim, stop, &status);
  const bool complete = end.at("complete");
  files.Close();
  const double wall =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();

  if (FaultInjected("run-seed:" + std::to_string(config.sim.seed)))
    throw std::runtime_error("injected fault (DUALGRID_FAULT) after the simulation");

  // Results first: nothing below may be lost to a figure that fails.
  const std::vector<eval::ScenarioMetrics> metrics = cosim.Metrics();
  std::vector<eval::ModeRuns> runs;
  nlohmann::json mj;
  for (std::size_t m = 0; m < modes.size(); ++m) {
    runs.push_back({mode_names[m], {metrics[m]}});
    mj["modes"][mode_names[m]] = metrics[m];
  }
  mj["scenario"] = config.sim.name;
  mj["seed"] = config.sim.seed;
  mj["steps"] = steps;
  mj["detections_per_step"] = steps ? static_cast<double>(cosim.total_detections()) / steps : 0.0;
  for (const auto& o : metrics.front().objects)
    mj["object_names"][std::to_string(o.id)] = ids.Name(o.id);
  WriteTextFile(out / "metrics.json", mj.dump(2) + "\n");
  WriteObjects(
      mode_names, metrics, ids, out / "objects.csv",
      recorded_run && !recorded_run->categories.empty() ? &recorded_run->categories : nullptr);
  eval::ComparisonTable table = eval::MakeComparisonTable(config.sim.name, runs);
  table.SetStatus(status);
  for (std::string& note :
       UnscoredNotes(metrics, ids, config.evaluation.tracking.min_frames_in_grid))
    table.AddNote(std::move(note));
  if (recorded_run)
    for (std::string note : RecordedNotes(*recorded_run, mode_names, metrics))
      table.AddNote(std::move(note));
  WriteTables(table, out);
  const WeightTraces& traces = files.traces();
  const std::string focus = traces.Focus();
  if (!focus.empty()) WriteWeights(traces.by_vehicle.at(focus), focus, out / "weights.csv");
  if (!options.run.quiet) std::cout << table.ToMarkdown() << "\n";
  // After the results, before the figures: a failure here costs only the replay.
  const bool recorded = recording && recording->Finish(mj["modes"], ids, complete, status);

  if (options.figures && !stop) {
    if (!focus.empty()) {
      const auto png = out / "figures" / "weights.png";
      TryFigures(
          png, options.figure_formats,
          [&](const auto& p) {
            RenderWeightTrace(traces.by_vehicle.at(focus), focus, mode_names[trace_mode],
                              config.filter.velocity_likelihood, p, options.figure_captions);
          },
          &warnings);
    }
    for (const bool v : {false, true}) {
      const auto png = out / "figures" / (v ? "tracked_share_v.png" : "tracked_share.png");
      const std::string what = v ? "D_v (tracked with the right velocity)" : "D";
      TryFigures(
          png, options.figure_formats,
          [&](const auto& p) {
            RenderTrackedShares(mode_names, RunTrackedShares(metrics, ids, v),
                                config.sim.name + ": tracked share " + what + " per object (seed " +
                                    std::to_string(config.sim.seed) + ")",
                                "tracked share " + what + " [%]", p, {}, options.figure_captions,
                                WordsFor(options.references));
          },
          &warnings);
    }
  }

  if (recorded && !stop && (options.video || options.viewer)) {
    std::signal(SIGPIPE, SIG_IGN);  // a failing ffmpeg must not kill the run before summary.json
    ReplayOptions ro;
    ro.run_dir = out;
    ro.quiet = options.run.quiet;
    try {
      const replay::Reader reader(out);
      if (options.viewer) WriteViewer(reader, ro);
      if (options.video) WriteVideo(reader, ro);
    } catch (const std::exception& e) {
      warnings.push_back(std::string("replay not written: ") + e.what());
      std::cerr << "dualgrid: warning: " << warnings.back() << "\n";
    }
  }

  // Written last: a run folder without summary.json did not finish.
  nlohmann::json summary = end;
  summary.update(nlohmann::json{{"status", status},
                                {"scenario", config.sim.name},
                                {"seed", config.sim.seed},
                                {"steps", steps},
                                {"simulated_s", simulated},
                                {"requested_s", config.sim.duration},
                                {"wall_s", wall},
                                {"warnings", warnings}});
  if (invariants) {
    summary["invariants_checked_steps"] = steps;
    summary["rss_mb"] = invariants->Samples(simulated);
  }
  // The grid frame as resolved at the ego's departure (docs/algorithm.md, "Grid frame").
  // The grid frame at the end, and how often it turned (grid.csv: every step's).
  summary["grid_frame"] = {{"frame", scenario::ToString(config.grid.frame)},
                           {"yaw_deg", RadToDeg(cosim.pipeline().grid_frame().yaw())},
                           {"realignments", cosim.pipeline().grid_realignments()}};
  // The radars as mounted on the ego's box as SUMO simulated it (config.json holds the rig as
  // read, on the scenario type's box: they differ for an ego of the user's route files).
  summary["sensors_mounted"] = nlohmann::json::array();
  if (cosim.pipeline().has_radar())  // mounted at the ego's departure
    for (const auto& s : cosim.pipeline().radar().sensors())
      summary["sensors_mounted"].push_back({{"name", s.name},
                                            {"x", s.mount.position.x()},
                                            {"y", s.mount.position.y()},
                                            {"yaw_deg", RadToDeg(s.mount.yaw)}});
  if (recorded_run) summary["input"] = recorded_run->input;
  summary["digests"] = OutputDigests(out);
  WriteTextFile(out / "summary.json", summary.dump(2) + "\n");
  if (!status.empty())
    std::cerr << "dualgrid: " << status << "; results in " << out.string() << "\n";
  if (stop) return StopExitCode();
  if (!options.run.quiet)
    std::cout << config.sim.name << ": " << steps
              << (recorded_run ? " filter cycles in " : " steps in ") << FormatFixed(wall, 1)
              << " s; results in " << out.string()
              << (warnings.empty() ? ""
                                   : " (" + std::to_string(warnings.size()) +
                                         " figure(s) not drawn, see the warnings above)")
              << "\n";
  return 0;
}

Command AddRunCommand(CLI::App& app, const CliContext& ctx) {
  auto o = std::make_shared<FilterRunOptions>();
  auto no_figures = std::make_shared<bool>(false);
  auto no_record = std::make_shared<bool>(false);
  o->run.network_dir = ctx.network_dir;
  auto* cmd = app.add_subcommand(
      "run",
      "Run SUMO, the radar and the grid filters (one per weight mode, same detections) "
      "and score them against the ground truth");
  AddRunOptions(cmd, &o->run, "Run folder (metrics, tables, figures, config)", true);
  AddFilterOptions(cmd, o.get(), no_figures.get());
  cmd->add_flag("--no-record", *no_record,
                "Do not record the replay frames (RUN_DIR/replay/; off anyway with --no-figures)");
  Opt(cmd, "--record-interval", &o->record_interval,
      "Time between recorded replay frames [s], rounded to whole steps")
      ->check(Number(0.001, 60.0, true));
  Opt(cmd, "--record-particles", &o->record_particles,
      "Particles recorded per mode and frame (an even subsample; 0: none)")
      ->check(WholeNumber(0, 1000000));
  cmd->add_flag("--video", o->video,
                "Also write the replay video (replay.mp4 and a GIF preview; needs ffmpeg) as "
                "`dualgrid replay` would");
  cmd->add_flag(
      "--viewer", o->viewer,
      "Also write the interactive viewer (replay.html) as `dualgrid replay --html` would");
  return {cmd, [o, no_figures, no_record] {
            o->figures = !*no_figures;
            o->record = o->figures && !*no_record;
            if ((o->video || o->viewer) && !o->record)
              throw std::invalid_argument(
                  "--video and --viewer need the recording: drop --no-record / --no-figures");
            return RunFilters(*o);
          }};
}

}  // namespace dualgrid::tools
